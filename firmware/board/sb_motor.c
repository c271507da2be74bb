#include "sb_motor.h"

#include <string.h>

#include "sb_codec.h"

/* The motor board around its common part (the first member). */
static sb_motor_board *motor(sb_board *b)
{
    return (sb_motor_board *)b;
}

static const sb_motor_board *motor_c(const sb_board *b)
{
    return (const sb_motor_board *)b;
}

static bool is_lift(uint8_t ch)
{
    return ch == 4 || ch == 5; /* MTF, MTB */
}

/* -- the motors ------------------------------------------------------------ */

static int16_t clamp(const sb_motor_board *b, uint8_t ch, int32_t mtps)
{
    int32_t limit = b->limit_mtps[ch];
    return (int16_t)(mtps > limit ? limit : (mtps < -limit ? -limit : mtps));
}

/* Sets one motor's speed (clamped) and mode; cancels its Move.  A motor
 * with a latched fault stays stopped in HOLD whatever it is told. */
static void set_one(sb_motor_board *b, uint8_t ch, int32_t mtps, uint8_t mode)
{
    const sb_hal *h = b->base.hal;
    if (b->latched[ch] != SB_FAULT_NONE) {
        mtps = 0;
        mode = SB_MODE_HOLD;
    }
    b->speed[ch] = clamp(b, ch, mtps);
    b->mode[ch] = mode;
    b->moving_to[ch] = false;
    h->set_motor(h->ctx, ch, b->speed[ch], mode == SB_MODE_BRAKE && !is_lift(ch));
}

/* A speed command's mode: RUN, or IDLE at 0. */
static void run_one(sb_motor_board *b, uint8_t ch, int32_t mtps)
{
    set_one(b, ch, mtps, mtps != 0 ? SB_MODE_RUN : SB_MODE_IDLE);
}

/* Every motor stopped, mode HOLD (e-stop, watchdog). */
static void halt(sb_board *base)
{
    sb_motor_board *b = motor(base);
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        set_one(b, ch, 0, SB_MODE_HOLD);
    }
}

static bool may_move(const sb_board *base)
{
    const sb_motor_board *b = motor_c(base);
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        if (b->mode[ch] == SB_MODE_RUN || b->mode[ch] == SB_MODE_MOVE) {
            return true;
        }
    }
    return false;
}

/* -- faults (section 3, "Faults") ----------------------------------------------- */

/* The motor's own fault as the HAL reports it: NONE, LIMIT (never latched),
 * or a latching one (OVERCURRENT, STALL, ENCODER, DRIVER; any other code
 * is taken for DRIVER). */
static uint8_t motor_fault(const sb_motor_board *b, uint8_t ch)
{
    const sb_hal *h = b->base.hal;
    uint8_t f = h->motor_fault ? h->motor_fault(h->ctx, ch) : SB_FAULT_NONE;
    if (f == SB_FAULT_NONE || f == SB_FAULT_LIMIT) return f;
    return (f >= SB_FAULT_OVERCURRENT && f <= SB_FAULT_DRIVER) ? f : (uint8_t)SB_FAULT_DRIVER;
}

/* Latches each motor's new latching fault: that motor stopped in HOLD, the
 * first one latched the board's Status.fault. */
static void see_faults(sb_motor_board *b)
{
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        uint8_t f = motor_fault(b, ch);
        if (f == SB_FAULT_NONE || f == SB_FAULT_LIMIT || b->latched[ch] != SB_FAULT_NONE) {
            continue;
        }
        b->latched[ch] = f;
        if (b->base.fault == SB_FAULT_NONE) b->base.fault = f;
        set_one(b, ch, 0, SB_MODE_HOLD);
    }
}

/* A motor's telemetry, its fault the first of: the board's latch, the
 * motor's latched fault, LIMIT, NONE. */
static sb_msg telemetry(sb_motor_board *b, uint8_t ch)
{
    sb_msg t;
    sb_msg_init(&t, SB_MOTOR_TELEMETRY);
    const sb_hal *h = b->base.hal;
    see_faults(b);
    uint8_t fault = sb_board_latch(&b->base);
    if (fault == SB_FAULT_NONE) fault = b->latched[ch];
    if (fault == SB_FAULT_NONE && motor_fault(b, ch) == SB_FAULT_LIMIT) fault = SB_FAULT_LIMIT;
    t.body.motor_telemetry.channel = ch;
    t.body.motor_telemetry.mode = b->mode[ch];
    t.body.motor_telemetry.fault = fault;
    t.body.motor_telemetry.speed_mtps = h->encoder_speed(h->ctx, ch);
    t.body.motor_telemetry.turns_mt = h->encoder_turns(h->ctx, ch);
    return t;
}

/* -- time ---------------------------------------------------------------------- */

/* The command hold and the Moves' stop points (after the common checks). */
static void poll(sb_board *base)
{
    sb_motor_board *b = motor(base);
    const sb_hal *h = base->hal;
    see_faults(b);
    if (base->hold_ms && sb_board_since(base, b->commanded_ms) > base->hold_ms) {
        bool any = false;
        for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
            if (b->mode[ch] == SB_MODE_RUN) {
                run_one(b, ch, 0); /* the command outlived its hold: stop, latch nothing */
                any = true;
            }
        }
        if (any) b->held_out++;
    }
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        if (!b->moving_to[ch]) continue;
        int32_t turns = h->encoder_turns(h->ctx, ch);
        if ((b->speed[ch] >= 0 && turns >= b->target[ch])
            || (b->speed[ch] < 0 && turns <= b->target[ch])) {
            run_one(b, ch, 0); /* the Move's stop point */
        }
    }
}

void sb_motor_poll(sb_motor_board *b)
{
    sb_board_poll(&b->base);
}

bool sb_motor_owns(const sb_motor_board *b, uint8_t session)
{
    return sb_board_owns(&b->base, session);
}

/* -- messages ------------------------------------------------------------------------- */

/* Speeds for the channels of mask (bit n: channel n), as SetWheelSpeeds,
 * SetLiftSpeeds and Run set them. */
static sb_msg speeds(sb_motor_board *b, uint8_t type, const int16_t v[SB_MOTORS], uint8_t mask)
{
    sb_ack_result r = sb_board_refusal(&b->base);
    if (r != SB_ACK_OK) return sb_board_ack(type, r);
    b->commanded_ms = sb_board_now(&b->base);
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        if (((unsigned)mask >> ch) & 1u) run_one(b, ch, v[ch]);
    }
    return sb_board_ack(type, SB_ACK_OK);
}

static sb_msg move(sb_motor_board *b, const sb_move *mv)
{
    sb_ack_result r = sb_board_refusal(&b->base);
    if (r != SB_ACK_OK) return sb_board_ack(SB_MOVE, r);
    const sb_hal *h = b->base.hal;
    uint8_t ch = mv->channel;
    see_faults(b);
    int32_t start = h->encoder_turns(h->ctx, ch);
    int32_t speed = mv->turns_mt >= 0 ? (int32_t)mv->speed_mtps : -(int32_t)mv->speed_mtps;
    b->commanded_ms = sb_board_now(&b->base);
    set_one(b, ch, speed, SB_MODE_MOVE);
    if (mv->turns_mt == 0) {
        run_one(b, ch, 0);
    } else if (b->mode[ch] == SB_MODE_MOVE) { /* not a motor held by its fault */
        b->moving_to[ch] = true;
        b->target[ch] = (int32_t)((int64_t)start + mv->turns_mt); /* the counter wraps */
    }
    return sb_board_ack(SB_MOVE, SB_ACK_OK);
}

static sb_msg stop_or_brake(sb_motor_board *b, uint8_t type, uint8_t mask)
{
    b->commanded_ms = sb_board_now(&b->base);
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        if (!(((unsigned)mask >> ch) & 1u)) continue;
        bool brake = type == SB_BRAKE && !is_lift(ch);
        set_one(b, ch, 0, brake ? SB_MODE_BRAKE : SB_MODE_IDLE);
    }
    return sb_board_ack(type, SB_ACK_OK);
}

/* StepTo and GetTruth, through a simulated plant's HAL (NOT_SUPPORTED without one). */
static sb_msg simulation(sb_motor_board *b, const sb_msg *msg)
{
    const sb_hal *h = b->base.hal;
    sb_msg r;
    if (msg->type == SB_STEP_TO) {
        uint32_t done = 0;
        if (!h->step_to || !h->step_to(h->ctx, msg->body.time_us.time_us, &done)) {
            return sb_board_ack(msg->type, SB_ACK_NOT_SUPPORTED);
        }
        sb_motor_poll(b); /* the plant moved on: the watchdog, the hold and the Moves */
        sb_msg_init(&r, SB_STEP_DONE);
        r.body.time_us.time_us = done;
        return r;
    }
    sb_plant_truth t;
    if (!h->truth || !h->truth(h->ctx, &t)) {
        return sb_board_ack(msg->type, SB_ACK_NOT_SUPPORTED);
    }
    sb_msg_init(&r, SB_TRUTH);
    r.body.truth.flags = t.fell ? 1u : 0u;
    r.body.truth.max_pitch_cdeg = t.max_pitch_cdeg;
    r.body.truth.offset_mm = t.offset_mm;
    return r;
}

static bool answer(sb_board *base, const sb_msg *msg, sb_reply *out)
{
    sb_motor_board *b = motor(base);
    const sb_msg_body *m = &msg->body;
    sb_msg r;
    switch (msg->type) {
    case SB_CLEAR: /* the common answer clears the rest (and Status.fault) */
        if (m->clear.mask & SB_CLEAR_FAULTS) memset(b->latched, 0, sizeof b->latched);
        return false;
    case SB_READ_ALL: {
        sb_msg tel[SB_MOTORS];
        for (uint8_t ch = 0; ch < SB_MOTORS; ch++) tel[ch] = telemetry(b, ch);
        r = sb_board_status(base);
        sb_board_emit(out, &r);
        for (uint8_t ch = 0; ch < SB_MOTORS; ch++) sb_board_emit(out, &tel[ch]);
        return true;
    }
    case SB_GET_MOTOR:
        r = telemetry(b, m->get_channel.channel);
        break;
    case SB_SET_WHEEL_SPEEDS: {
        const int16_t v[SB_MOTORS] = {m->wheel_speeds.mwf, m->wheel_speeds.mwb,
                                      m->wheel_speeds.mwr, m->wheel_speeds.mwl, 0, 0};
        r = speeds(b, msg->type, v, 0x0F);
        break;
    }
    case SB_SET_LIFT_SPEEDS: {
        const int16_t v[SB_MOTORS] = {0, 0, 0, 0, m->lift_speeds.mtf, m->lift_speeds.mtb};
        r = speeds(b, msg->type, v, 0x30);
        break;
    }
    case SB_RUN: {
        int16_t v[SB_MOTORS] = {0};
        v[m->run.channel] = m->run.speed_mtps;
        r = speeds(b, msg->type, v, (uint8_t)(1u << m->run.channel));
        break;
    }
    case SB_MOVE:
        r = move(b, &m->move);
        break;
    case SB_STOP: case SB_BRAKE:
        r = stop_or_brake(b, msg->type, m->motor_mask.mask);
        break;
    case SB_STEP_TO: case SB_GET_TRUTH:
        r = simulation(b, msg);
        break;
    default:
        return false;
    }
    sb_board_emit(out, &r);
    return true;
}

static const sb_board_ops MOTOR_OPS = {poll, halt, may_move, answer};

void sb_motor_init(sb_motor_board *b, const sb_hal *hal, const sb_motor_config *cfg)
{
    memset(b, 0, sizeof *b);
    const sb_board_id id = {SB_BOARD_MOTOR, SB_MOTORS, cfg->serial, cfg->boot, cfg->simulated,
                            cfg->lockstep};
    sb_board_caps caps = SB_MOTOR_BOARD;
    caps.simulation = hal->step_to != NULL; /* a board on a simulated plant */
    sb_board_init(&b->base, hal, &MOTOR_OPS, &id, &caps);
    memcpy(b->limit_mtps, cfg->limit_mtps, sizeof b->limit_mtps);
    b->commanded_ms = b->base.start_ms;
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        hal->set_motor(hal->ctx, ch, 0, false);
    }
}

size_t sb_motor_frame(sb_motor_board *b, const sb_frame *f, uint8_t out[SB_MAX_WIRE])
{
    return sb_board_frame(&b->base, f, out);
}
