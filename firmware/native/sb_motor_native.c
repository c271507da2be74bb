/* sb_motor_native: the motor board's firmware (firmware/board) on Linux,
 * speaking the serial protocol (docs/protocol.md, section 5).
 *
 *   sb_motor_native [--serial N] [--host-fd N] [--plant-fd N] [PATH]
 *
 * The host's line: an inherited descriptor (--host-fd), the tty at PATH, or
 * else a new pty whose slave path is printed on stdout's first line (what a
 * host opens: serial://PATH).  The motors: the simulated robot over the plant
 * link on an inherited socket (--plant-fd; firmware/plant), which also gives
 * the board its serial number and speed limits; without it, a trivial plant
 * (plant.h).  SIGUSR1 presses the board's e-stop button, SIGUSR2 releases
 * it; SIGTERM or SIGINT ends it, printing its counts on stderr, as does the
 * plant link closing. */
#include <stdio.h>

#include "plant.h"
#include "sb_motor.h"
#include "sb_native.h"
#include "sb_plant.h"

#define PLANT_TIMEOUT_MS 2000u

static plant trivial;

static void advance_trivial(uint32_t wall_ms)
{
    trivial.estop_pressed = sb_native_button != 0;
    plant_advance(&trivial, wall_ms);
}

int main(int argc, char **argv)
{
    sb_native_args a = {"sb_motor_native", 0, -1, -1, NULL};
    int bad = sb_native_args_parse(argc, argv, &a);
    if (bad) return bad;
    static sb_plant plant_link;
    static sb_motor_board board;
    static int plant_fd;
    sb_plant_io io = sb_native_plant_io(&plant_fd);
    sb_hal hal;
    sb_motor_config cfg = {a.serial ? (uint16_t)a.serial : 1u, sb_native_boot_id(), {0}, true,
                           false};
    sb_native_board nb = {&board.base, NULL, advance_trivial};
    if (a.plant_fd >= 0) {
        plant_fd = a.plant_fd;
        if (!sb_plant_hello(&plant_link, &io, 1, PLANT_TIMEOUT_MS)) {
            fprintf(stderr, "sb_motor_native: the plant on descriptor %d did not answer\n",
                    plant_fd);
            return 1;
        }
        hal = sb_plant_hal(&plant_link);
        if (!a.serial) cfg.serial = plant_link.info.serial;
        cfg.lockstep = plant_link.info.lockstep;
        for (unsigned ch = 0; ch < SB_MOTORS; ch++) {
            cfg.limit_mtps[ch] = plant_link.info.limit_mtps[ch];
        }
        nb.plant = &plant_link;
    } else {
        plant_init(&trivial);
        hal = plant_hal(&trivial);
        plant_limits(cfg.limit_mtps);
    }
    int fd = sb_native_open_host(&a);
    if (fd < 0) return 1;
    sb_motor_init(&board, &hal, &cfg);
    return sb_native_serve(fd, &a, &nb);
}
