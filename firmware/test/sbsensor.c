/* The sensor board (firmware/board/sb_sensor.c) on a scripted clock and a
 * scripted sensor plant, one command a line on stdin, one answer a line on
 * stdout, so that tests/firmware/test_sensor_board_steps.py can hold it
 * against the Python fake sensor board step by step:
 *
 *   t MS                          the clock at MS ms (never back), then poll   -> ok
 *   range CH CODE MM US           channel CH's latest measurement: SensorCode,
 *                                 distance (mm), its time (us on the clock)    -> ok
 *   range CH none                 channel CH has never measured                 -> ok
 *   imu AXIS CODE CDEG DDPS US    IMU axis AXIS's latest sample: ImuCode,
 *                                 angle (0.01 deg), rate (0.1 deg/s), its time -> ok
 *   imu none                      no IMU fitted                                 -> ok
 *   w HEX                         stuffed bytes (with their delimiters), fed one
 *                                 by one -> HEX... of the reply frames (stuffed,
 *                                 delimited), or "-" for none
 *
 * Started as "sbsensor BOOT CHANNELS [nous] [norange] [noimu]": Owner.boot is
 * BOOT (decimal), the board has CHANNELS range channels (4 or 6); nous
 * leaves the HAL's now_us out (the board counts now_ms * 1000), norange and
 * noimu its range_read and imu_read.  Every channel starts never measured,
 * the IMU absent. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sb_reader.h"
#include "sbline.h"
#include "sb_sensor.h"

#define LINE_MAX_CHARS 4096

typedef struct {
    uint32_t now_ms;
    bool measured[SB_SENSOR_CHANNELS_MAX];
    sb_range range[SB_SENSOR_CHANNELS_MAX];
    bool imu_fitted;
    sb_imu_sample imu[SB_IMU_AXES];
} script_plant;

static char line[LINE_MAX_CHARS];

static uint32_t now_ms(void *ctx)
{
    return ((script_plant *)ctx)->now_ms;
}

static uint32_t now_us(void *ctx)
{
    return ((script_plant *)ctx)->now_ms * 1000u;
}

static bool range_read(void *ctx, uint8_t ch, sb_range *out)
{
    script_plant *p = ctx;
    if (!p->measured[ch]) return false;
    *out = p->range[ch];
    return true;
}

static bool imu_read(void *ctx, uint8_t axis, sb_imu_sample *out)
{
    script_plant *p = ctx;
    if (!p->imu_fitted) return false;
    *out = p->imu[axis];
    return true;
}

static bool has_arg(int argc, char **argv, const char *name)
{
    for (int i = 3; i < argc; i++) {
        if (strcmp(argv[i], name) == 0) return true;
    }
    return false;
}

/* "range CH ..." and "imu ..." lines; false for a malformed one. */
static bool set_reading(script_plant *p, const char *args, bool is_range)
{
    unsigned a = 0, code = 0;
    long v1 = 0, v2 = 0;
    unsigned long us = 0;
    if (is_range) {
        char word[8];
        if (sscanf(args, "%u %7s", &a, word) == 2 && strcmp(word, "none") == 0
            && a < SB_SENSOR_CHANNELS_MAX) {
            p->measured[a] = false;
            return true;
        }
        if (sscanf(args, "%u %u %ld %lu", &a, &code, &v1, &us) != 4 || a >= SB_SENSOR_CHANNELS_MAX)
            return false;
        p->measured[a] = true;
        p->range[a] = (sb_range){(uint8_t)code, (uint16_t)v1, (uint32_t)us};
        return true;
    }
    if (strncmp(args, "none", 4) == 0) {
        p->imu_fitted = false;
        return true;
    }
    if (sscanf(args, "%u %u %ld %ld %lu", &a, &code, &v1, &v2, &us) != 5 || a >= SB_IMU_AXES)
        return false;
    p->imu_fitted = true;
    p->imu[a] = (sb_imu_sample){(uint8_t)code, (int16_t)v1, (int16_t)v2, (uint32_t)us};
    return true;
}

int main(int argc, char **argv)
{
    static script_plant world;
    static sb_sensor_board board;
    static sb_reader reader;
    sb_hal hal = {0};
    hal.ctx = &world;
    hal.now_ms = now_ms;
    hal.now_us = has_arg(argc, argv, "nous") ? NULL : now_us;
    hal.range_read = has_arg(argc, argv, "norange") ? NULL : range_read;
    hal.imu_read = has_arg(argc, argv, "noimu") ? NULL : imu_read;
    sb_sensor_config cfg = {2, argc > 1 ? (uint32_t)strtoul(argv[1], NULL, 10) : 1u,
                            (uint8_t)(argc > 2 ? strtoul(argv[2], NULL, 10) : 4u), true, false};
    sb_sensor_init(&board, &hal, &cfg);
    sb_reader_init(&reader);
    while (fgets(line, sizeof line, stdin)) {
        line[strcspn(line, "\r\n")] = 0;
        if (line[0] == 't' && line[1] == ' ') {
            world.now_ms = (uint32_t)strtoul(line + 2, NULL, 10);
            sb_sensor_poll(&board);
            puts("ok");
        } else if (strncmp(line, "range ", 6) == 0 || strncmp(line, "imu ", 4) == 0) {
            bool is_range = line[0] == 'r';
            puts(set_reading(&world, line + (is_range ? 6 : 4), is_range) ? "ok" : "err reading");
        } else if (line[0] == 'w' && line[1] == ' ') {
            sb_line_feed(line + 2, &reader, &board.base);
        } else {
            puts("err command");
        }
        fflush(stdout);
    }
    return 0;
}
