#define _XOPEN_SOURCE 700 /* posix_openpt, grantpt, unlockpt, ptsname */
#define _DEFAULT_SOURCE   /* cfmakeraw */
#include "sb_native.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "sb_reader.h"

volatile sig_atomic_t sb_native_button = 0;
static volatile sig_atomic_t stopping = 0;

static void on_stop(int sig)
{
    (void)sig;
    stopping = 1;
}

static void on_button(int sig)
{
    sb_native_button = sig == SIGUSR1;
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

static int usage(const char *name, const char *why)
{
    fprintf(stderr,
            "%s: %s; usage: %s [--serial 1..65535] [--host-fd N] [--plant-fd N] [PATH]\n", name,
            why, name);
    return 2;
}

static bool number(const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || *end || end == s || v < lo || v > hi) return false;
    *out = v;
    return true;
}

int sb_native_args_parse(int argc, char **argv, sb_native_args *a)
{
    a->serial = 0;
    a->host_fd = -1;
    a->plant_fd = -1;
    a->path = NULL;
    for (int i = 1; i < argc; i++) {
        long v;
        if (strcmp(argv[i], "--serial") == 0 && i + 1 < argc) {
            if (!number(argv[++i], 1, 65535, &v)) return usage(a->name, "--serial takes 1..65535");
            a->serial = v;
        } else if (strcmp(argv[i], "--host-fd") == 0 && i + 1 < argc) {
            if (!number(argv[++i], 0, 65535, &v)) return usage(a->name, "--host-fd takes a descriptor");
            a->host_fd = (int)v;
        } else if (strcmp(argv[i], "--plant-fd") == 0 && i + 1 < argc) {
            if (!number(argv[++i], 0, 65535, &v)) return usage(a->name, "--plant-fd takes a descriptor");
            a->plant_fd = (int)v;
        } else if (argv[i][0] == '-' || a->path != NULL) {
            return usage(a->name, "unknown argument");
        } else {
            a->path = argv[i];
        }
    }
    if (a->host_fd >= 0 && a->path != NULL) return usage(a->name, "--host-fd and PATH both given");
    return 0;
}

/* A new pty: its master returned, its slave kept open (so the pty outlives a
 * host that closes and reopens it), its path printed. */
static int open_pty(void)
{
    int master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) return -1;
    const char *path = ptsname(master);
    if (path == NULL) return -1;
    int slave = open(path, O_RDWR | O_NOCTTY);
    if (slave < 0 || raw(slave) != 0 || raw(master) != 0) return -1;
    printf("%s\n", path);
    fflush(stdout);
    return master;
}

int sb_native_open_host(const sb_native_args *a)
{
    int fd = a->host_fd;
    if (fd < 0 && a->path == NULL) {
        fd = open_pty();
        if (fd < 0) {
            fprintf(stderr, "%s: cannot open a pseudo-terminal: %s\n", a->name, strerror(errno));
            return -1;
        }
    } else if (fd < 0) {
        fd = open(a->path, O_RDWR | O_NOCTTY);
        if (fd < 0 || raw(fd) != 0) {
            fprintf(stderr, "%s: cannot open %s as a raw tty: %s\n", a->name, a->path,
                    strerror(errno));
            return -1;
        }
    }
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
    return fd;
}

/* -- the plant link on a socket --------------------------------------------------------- */

static void plant_send(void *ctx, const uint8_t *p, size_t n)
{
    int fd = *(int *)ctx;
    while (n > 0) {
        ssize_t w = write(fd, p, n);
        if (w > 0) {
            p += w;
            n -= (size_t)w;
        } else if (w < 0 && errno != EINTR) {
            return; /* the plant is gone: the next answer will not come */
        }
    }
}

static int plant_recv(void *ctx, uint32_t timeout_ms)
{
    static uint8_t buf[512];
    static size_t have = 0, next = 0;
    int fd = *(int *)ctx;
    if (next < have) return buf[next++];
    struct pollfd in = {fd, POLLIN, 0};
    if (poll(&in, 1, (int)timeout_ms) <= 0) return -1;
    ssize_t n = read(fd, buf, sizeof buf);
    if (n <= 0) {
        stopping = 1; /* the plant closed its end: nothing more to serve */
        return -1;
    }
    have = (size_t)n;
    next = 1;
    return buf[0];
}

sb_plant_io sb_native_plant_io(int *fd)
{
    signal(SIGPIPE, SIG_IGN); /* a plant gone is seen as EOF or an error, not a signal */
    sb_plant_io io = {fd, plant_send, plant_recv};
    return io;
}

uint32_t sb_native_boot_id(void)
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

/* -- serving ------------------------------------------------------------------------------ */

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

/* Brings the board's plant to the present. */
static void refresh(const sb_native_board *nb, uint32_t wall_ms)
{
    if (nb->plant == NULL) {
        nb->advance(wall_ms);
        return;
    }
    nb->plant->estop_pressed = sb_native_button != 0;
    nb->plant->flags = sb_board_status(nb->board).body.status.flags;
    sb_plant_query(nb->plant);
}

int sb_native_serve(int fd, const sb_native_args *a, const sb_native_board *nb)
{
    signal(SIGTERM, on_stop);
    signal(SIGINT, on_stop);
    signal(SIGUSR1, on_button);
    signal(SIGUSR2, on_button);
    static sb_reader reader;
    static uint8_t reply[SB_MAX_WIRE];
    sb_reader_init(&reader);
    uint64_t t0 = mono_ms();
    unsigned overflows = 0;
    const struct timespec pause_10ms = {0, 10000000L};
    while (!stopping) {
        struct pollfd in = {fd, POLLIN, 0};
        int ready = poll(&in, 1, 1);
        refresh(nb, (uint32_t)(mono_ms() - t0));
        sb_board_poll(nb->board);
        if (ready <= 0 || !(in.revents & POLLIN)) continue;
        uint8_t buf[512];
        ssize_t n = read(fd, buf, sizeof buf);
        if (n <= 0) {
            if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
                if (a->host_fd >= 0 && n == 0) break; /* the line's other end closed */
                nanosleep(&pause_10ms, NULL);          /* a pty with no host yet */
            }
            continue;
        }
        for (ssize_t i = 0; i < n; i++) {
            sb_frame frame;
            if (!sb_reader_push(&reader, buf[i], &frame)) continue;
            size_t len = sb_board_frame(nb->board, &frame, reply);
            if (len > 0) send_reply(fd, reply, len, &overflows);
        }
    }
    const sb_board *b = nb->board;
    fprintf(stderr,
            "%s: %u frames, %u duplicates answered from the cache, %u replies cut, %u CRC "
            "errors, %u malformed, %u overruns, %u replies dropped\n",
            a->name, (unsigned)b->frames, (unsigned)b->duplicates, (unsigned)b->cut,
            (unsigned)reader.stats.crc_errors, (unsigned)reader.stats.malformed,
            (unsigned)reader.stats.overruns, overflows);
    close(fd);
    return 0;
}
