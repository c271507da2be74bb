/* The motor board's hardware abstraction: what sb_motor.c asks of the
 * hardware, and nothing else.  A port fills one sb_hal with its functions;
 * ctx is handed back to each.  Every call is quick and never blocks. */
#ifndef SB_HAL_H
#define SB_HAL_H

#include <stdbool.h>
#include <stdint.h>

typedef struct {
    void *ctx;
    /* Milliseconds since power-up (wrapping at 2^32). */
    uint32_t (*now_ms)(void *ctx);
    /* Drive channel ch at speed_mtps (milli-turns/s, section 1's signs;
     * already clamped to the channel's limit).  brake: speed 0 with the
     * wheel braked actively rather than left to coast (a lift holds at 0
     * either way). */
    void (*set_motor)(void *ctx, uint8_t ch, int16_t speed_mtps, bool brake);
    /* The encoder of channel ch: turns since power-up (milli-turns) and
     * the measured speed (milli-turns/s). */
    int32_t (*encoder_turns)(void *ctx, uint8_t ch);
    int16_t (*encoder_speed)(void *ctx, uint8_t ch);
    /* The motor's own fault (MotorFault: 0 NONE, 6 LIMIT, 7 DRIVER, ...);
     * reported in its telemetry, not latched. */
    uint8_t (*motor_fault)(void *ctx, uint8_t ch);
    /* Whether the board's e-stop input (a button) is pressed; NULL: none. */
    bool (*estop_input)(void *ctx);
} sb_hal;

#endif
