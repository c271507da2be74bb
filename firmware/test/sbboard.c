/* The motor board (firmware/board) on the native plant (firmware/native/plant.c)
 * and a scripted clock, one command a line on stdin, one answer a line on
 * stdout, so that tests/firmware/test_motor_board.py can hold it against the
 * Python fake motor board step by step:
 *
 *   t MS        the plant and the board's clock at MS ms (never back), then poll -> ok
 *   w HEX       stuffed bytes (with their delimiters), fed one by one   -> HEX... of the
 *               reply frames (stuffed, delimited), or "-" for none
 *   b 0|1       the e-stop input released or pressed                   -> ok
 *   f CH CODE   motor CH's own fault is CODE (MotorFault; 0: none)       -> ok
 *   s           the plant: each motor's position (micro-turns), then each
 *               motor's commanded speed (milli-turns/s)                 -> 12 numbers
 *
 * Started as "sbboard BOOT [LIFT_MT]": Owner.boot is BOOT (decimal); the
 * lifts start at +LIFT_MT (MTF) and -LIFT_MT (MTB) milli-turns, near the
 * ends of their stroke if asked. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plant.h"
#include "sb_motor.h"
#include "sb_reader.h"
#include "sbline.h"

#define LINE_MAX_CHARS 4096

static char line[LINE_MAX_CHARS];

int main(int argc, char **argv)
{
    static plant world;
    static sb_motor_board board;
    static sb_reader reader;
    plant_init(&world);
    if (argc > 2) {
        int64_t lift_umt = (int64_t)strtol(argv[2], NULL, 10) * 1000;
        world.position_umt[4] = lift_umt;
        world.position_umt[5] = -lift_umt;
    }
    sb_hal hal = plant_hal(&world);
    sb_motor_config cfg = {1, argc > 1 ? (uint32_t)strtoul(argv[1], NULL, 10) : 1u, {0}, true, false};
    plant_limits(cfg.limit_mtps);
    sb_motor_init(&board, &hal, &cfg);
    sb_reader_init(&reader);
    while (fgets(line, sizeof line, stdin)) {
        line[strcspn(line, "\r\n")] = 0;
        if (line[0] == 't' && line[1] == ' ') {
            plant_advance(&world, (uint32_t)strtoul(line + 2, NULL, 10));
            sb_motor_poll(&board);
            puts("ok");
        } else if (line[0] == 'f' && line[1] == ' ') {
            char *end;
            unsigned long ch = strtoul(line + 2, &end, 10);
            if (ch < SB_MOTORS) world.injected[ch] = (uint8_t)strtoul(end, NULL, 10);
            puts("ok");
        } else if (line[0] == 'b' && line[1] == ' ') {
            world.estop_pressed = line[2] == '1';
            puts("ok");
        } else if (line[0] == 'w' && line[1] == ' ') {
            sb_line_feed(line + 2, &reader, &board.base);
        } else if (line[0] == 's') {
            for (int ch = 0; ch < SB_MOTORS; ch++) printf("%lld ", (long long)world.position_umt[ch]);
            for (int ch = 0; ch < SB_MOTORS; ch++) printf("%d ", world.command[ch]);
            puts("");
        } else {
            puts("err command");
        }
        fflush(stdout);
    }
    return 0;
}
