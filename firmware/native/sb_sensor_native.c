/* sb_sensor_native: the sensor board's firmware (firmware/board) on Linux,
 * speaking the serial protocol (docs/protocol.md, section 5).
 *
 *   sb_sensor_native --plant-fd N [--serial N] [--host-fd N] [PATH]
 *
 * The host's line as sb_motor_native's (an inherited descriptor, a tty's
 * path, or a new pty whose path is printed).  The range sensors and the IMU
 * are the simulated robot's, over the plant link on an inherited socket
 * (--plant-fd; firmware/plant), which also gives the board its serial
 * number and its channels (4, or 6 with the side pair).  SIGTERM or SIGINT
 * ends it, printing its counts on stderr, as does the plant link closing. */
#include <stdio.h>

#include "sb_native.h"
#include "sb_plant.h"
#include "sb_sensor.h"

#define PLANT_TIMEOUT_MS 2000u

int main(int argc, char **argv)
{
    sb_native_args a = {"sb_sensor_native", 0, -1, -1, NULL};
    int bad = sb_native_args_parse(argc, argv, &a);
    if (bad) return bad;
    if (a.plant_fd < 0) {
        fprintf(stderr, "sb_sensor_native: --plant-fd is needed: its sensors are the plant's\n");
        return 2;
    }
    static sb_plant plant_link;
    static sb_sensor_board board;
    static int plant_fd;
    plant_fd = a.plant_fd;
    sb_plant_io io = sb_native_plant_io(&plant_fd);
    if (!sb_plant_hello(&plant_link, &io, 2, PLANT_TIMEOUT_MS)) {
        fprintf(stderr, "sb_sensor_native: the plant on descriptor %d did not answer\n", plant_fd);
        return 1;
    }
    sb_hal hal = sb_plant_hal(&plant_link);
    sb_sensor_config cfg = {a.serial ? (uint16_t)a.serial : plant_link.info.serial,
                            sb_native_boot_id(), plant_link.info.channels, true,
                            plant_link.info.lockstep};
    sb_native_board nb = {&board.base, &plant_link, NULL};
    int fd = sb_native_open_host(&a);
    if (fd < 0) return 1;
    sb_sensor_init(&board, &hal, &cfg);
    return sb_native_serve(fd, &a, &nb);
}
