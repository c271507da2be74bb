/* sb_motor_native: the motor board's firmware (firmware/board) on Linux,
 * speaking the serial protocol (docs/protocol.md, section 5) on a
 * pseudo-terminal, with a trivial plant behind its HAL (plant.h).
 *
 *   sb_motor_native [--serial N] [PATH]
 *
 * Without PATH it opens a new pty and prints its slave path on the first
 * line of stdout (what a host opens: serial://PATH); with PATH it opens
 * that tty.  SIGUSR1 presses the board's e-stop button, SIGUSR2 releases
 * it; SIGTERM or SIGINT ends it, printing its counts on stderr. */
#define _XOPEN_SOURCE 700 /* posix_openpt, grantpt, unlockpt, ptsname */
#define _DEFAULT_SOURCE   /* cfmakeraw */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "plant.h"
#include "sb_motor.h"
#include "sb_reader.h"

static volatile sig_atomic_t stopping = 0;
static volatile sig_atomic_t button = 0;

static void on_stop(int sig)
{
    (void)sig;
    stopping = 1;
}

static void on_button(int sig)
{
    button = sig == SIGUSR1;
}

static uint64_t mono_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000u + (uint64_t)ts.tv_nsec / 1000000u;
}

static int raw(int fd)
{
    struct termios t;
    if (tcgetattr(fd, &t) != 0) return -1;
    cfmakeraw(&t);
    return tcsetattr(fd, TCSANOW, &t);
}

/* A new pty: its master in *master, its slave kept open in *slave (so the
 * pty outlives a host that closes and reopens it), its path printed. */
static int open_pty(int *master, int *slave)
{
    *master = posix_openpt(O_RDWR | O_NOCTTY);
    if (*master < 0 || grantpt(*master) != 0 || unlockpt(*master) != 0) return -1;
    const char *path = ptsname(*master);
    if (path == NULL) return -1;
    *slave = open(path, O_RDWR | O_NOCTTY);
    if (*slave < 0 || raw(*slave) != 0 || raw(*master) != 0) return -1;
    printf("%s\n", path);
    fflush(stdout);
    return 0;
}

/* Writes a reply, or drops what the line will not take within 50 ms (a
 * UART sends into the void when nobody listens). */
static void send_reply(int fd, const uint8_t *p, size_t n, unsigned *overflows)
{
    while (n > 0) {
        ssize_t w = write(fd, p, n);
        if (w > 0) {
            p += w;
            n -= (size_t)w;
            continue;
        }
        if (w < 0 && errno != EAGAIN && errno != EINTR) return;
        struct pollfd out = {fd, POLLOUT, 0};
        if (poll(&out, 1, 50) <= 0) {
            (*overflows)++;
            return;
        }
    }
}

static uint32_t boot_id(void)
{
    uint32_t id = 0;
    FILE *f = fopen("/dev/urandom", "rb");
    if (f != NULL) {
        if (fread(&id, sizeof id, 1, f) != 1) id = 0;
        fclose(f);
    }
    if (id == 0) id = (uint32_t)mono_ms() ^ (uint32_t)getpid();
    return id ? id : 1;
}

static int usage(const char *why)
{
    fprintf(stderr, "sb_motor_native: %s; usage: sb_motor_native [--serial 1..65535] [PATH]\n",
            why);
    return 2;
}

int main(int argc, char **argv)
{
    long serial = 1;
    const char *path = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--serial") == 0 && i + 1 < argc) {
            char *end;
            serial = strtol(argv[++i], &end, 10);
            if (*end || serial < 1 || serial > 65535) return usage("--serial takes 1..65535");
        } else if (argv[i][0] == '-' || path != NULL) {
            return usage("unknown argument");
        } else {
            path = argv[i];
        }
    }
    int fd, slave = -1;
    if (path == NULL) {
        if (open_pty(&fd, &slave) != 0) {
            fprintf(stderr, "sb_motor_native: cannot open a pseudo-terminal: %s\n",
                    strerror(errno));
            return 1;
        }
    } else {
        fd = open(path, O_RDWR | O_NOCTTY);
        if (fd < 0 || raw(fd) != 0) {
            fprintf(stderr, "sb_motor_native: cannot open %s as a raw tty: %s\n", path,
                    strerror(errno));
            return 1;
        }
    }
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
    signal(SIGTERM, on_stop);
    signal(SIGINT, on_stop);
    signal(SIGUSR1, on_button);
    signal(SIGUSR2, on_button);

    static plant world;
    static sb_motor_board board;
    static sb_reader reader;
    static uint8_t reply[SB_MAX_WIRE];
    uint64_t t0 = mono_ms();
    plant_init(&world);
    sb_hal hal = plant_hal(&world);
    sb_motor_config cfg = {(uint16_t)serial, boot_id(), {0}, true, false};
    plant_limits(cfg.limit_mtps);
    sb_motor_init(&board, &hal, &cfg);
    sb_reader_init(&reader);
    unsigned overflows = 0;
    const struct timespec pause_10ms = {0, 10000000L};

    while (!stopping) {
        struct pollfd in = {fd, POLLIN, 0};
        int ready = poll(&in, 1, 1);
        world.estop_pressed = button != 0;
        plant_advance(&world, (uint32_t)(mono_ms() - t0));
        sb_motor_poll(&board);
        if (ready <= 0 || !(in.revents & POLLIN)) continue;
        uint8_t buf[512];
        ssize_t n = read(fd, buf, sizeof buf);
        if (n <= 0) {
            if (n == 0 || (errno != EAGAIN && errno != EINTR)) nanosleep(&pause_10ms, NULL); /* no host yet */
            continue;
        }
        for (ssize_t i = 0; i < n; i++) {
            sb_frame frame;
            if (!sb_reader_push(&reader, buf[i], &frame)) continue;
            size_t len = sb_motor_frame(&board, &frame, reply);
            if (len > 0) send_reply(fd, reply, len, &overflows);
        }
    }
    fprintf(stderr,
            "sb_motor_native: %u frames, %u duplicates answered from the cache, %u CRC errors, "
            "%u malformed, %u overruns, %u replies cut, %u replies dropped\n",
            (unsigned)board.base.frames, (unsigned)board.base.duplicates, (unsigned)reader.stats.crc_errors,
            (unsigned)reader.stats.malformed, (unsigned)reader.stats.overruns,
            (unsigned)board.base.cut, overflows);
    if (slave >= 0) close(slave);
    close(fd);
    return 0;
}
