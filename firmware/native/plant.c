#include "plant.h"

#include <string.h>

static bool lift(uint8_t ch)
{
    return ch == 4 || ch == 5;
}

void plant_limits(int16_t limit_mtps[SB_MOTORS])
{
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        limit_mtps[ch] = lift(ch) ? PLANT_LIFT_LIMIT_MTPS : PLANT_WHEEL_LIMIT_MTPS;
    }
}

void plant_init(plant *p)
{
    memset(p, 0, sizeof *p);
}

void plant_advance(plant *p, uint32_t t_ms)
{
    uint32_t dt = t_ms - p->now_ms;
    if (dt == 0) {
        return; /* nothing moves in no time: the measured speeds stay those of this instant */
    }
    p->now_ms = t_ms;
    int16_t limit[SB_MOTORS];
    plant_limits(limit);
    const int64_t stroke = (int64_t)PLANT_LIFT_STROKE_MT * 1000;
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        int32_t v = p->command[ch];
        v = v > limit[ch] ? limit[ch] : (v < -limit[ch] ? -limit[ch] : v);
        int64_t pos = p->position_umt[ch] + (int64_t)v * dt; /* mturn/s x ms = micro-turns */
        p->at_limit[ch] = false;
        if (lift(ch) && (pos > stroke || pos < -stroke)) {
            pos = pos > stroke ? stroke : -stroke;
            p->at_limit[ch] = true;
            v = 0;
        }
        p->position_umt[ch] = pos;
        p->measured[ch] = (int16_t)v;
    }
}

static uint32_t now_ms(void *ctx)
{
    return ((plant *)ctx)->now_ms;
}

static void set_motor(void *ctx, uint8_t ch, int16_t speed_mtps, bool brake)
{
    (void)brake; /* the trivial plant stops at once either way */
    ((plant *)ctx)->command[ch] = speed_mtps;
}

static int32_t encoder_turns(void *ctx, uint8_t ch)
{
    int64_t umt = ((plant *)ctx)->position_umt[ch];
    return (int32_t)(umt >= 0 ? (umt + 500) / 1000 : -((-umt + 500) / 1000));
}

static int16_t encoder_speed(void *ctx, uint8_t ch)
{
    return ((plant *)ctx)->measured[ch];
}

static uint8_t motor_fault(void *ctx, uint8_t ch)
{
    const plant *p = ctx;
    if (p->injected[ch] != SB_FAULT_NONE) return p->injected[ch];
    return p->at_limit[ch] ? SB_FAULT_LIMIT : SB_FAULT_NONE;
}

static bool estop_input(void *ctx)
{
    return ((plant *)ctx)->estop_pressed;
}

sb_hal plant_hal(plant *p)
{
    sb_hal h = {0};
    h.ctx = p;
    h.now_ms = now_ms;
    h.set_motor = set_motor;
    h.encoder_turns = encoder_turns;
    h.encoder_speed = encoder_speed;
    h.motor_fault = motor_fault;
    h.estop_input = estop_input;
    return h;
}
