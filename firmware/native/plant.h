/* A trivial plant behind the motor board's HAL, for the native program:
 * each motor's counter integrates its commanded speed, clamped to the
 * motor's limit (the default robot's: wheels 1 turn/s, lifts 10 turns/s);
 * a lift stops at the end of its stroke (+-105 turns: 0.21 m at 2 mm a
 * turn) and says LIMIT while it is driven against it. */
#ifndef SB_TRIVIAL_PLANT_H
#define SB_TRIVIAL_PLANT_H

#include <stdbool.h>
#include <stdint.h>

#include "sb_hal.h"
#include "sb_motor.h"

#define PLANT_WHEEL_LIMIT_MTPS 1000
#define PLANT_LIFT_LIMIT_MTPS 10000
#define PLANT_LIFT_STROKE_MT 105000

typedef struct {
    uint32_t now_ms;                /* the plant's time (set by its owner) */
    int16_t command[SB_MOTORS];     /* milli-turns/s */
    int64_t position_umt[SB_MOTORS]; /* micro-turns */
    int16_t measured[SB_MOTORS];
    bool at_limit[SB_MOTORS];
    uint8_t injected[SB_MOTORS];    /* a motor's own fault set by a test (MotorFault; 0: none) */
    volatile bool estop_pressed;
} plant;

void plant_init(plant *p);
/* Advances every motor to time t_ms. */
void plant_advance(plant *p, uint32_t t_ms);
/* The HAL on this plant. */
sb_hal plant_hal(plant *p);
/* The board's limits for this plant's motors. */
void plant_limits(int16_t limit_mtps[SB_MOTORS]);

#endif
