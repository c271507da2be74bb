#include "sb_motor.h"

#include <string.h>

#include "sb_check.h"
#include "sb_codec.h"

static uint32_t now(const sb_motor_board *b)
{
    return b->hal->now_ms(b->hal->ctx);
}

/* Milliseconds from then to now, wrapping. */
static uint32_t since(const sb_motor_board *b, uint32_t then)
{
    return (uint32_t)(now(b) - then);
}

static bool is_lift(uint8_t ch)
{
    return ch == 4 || ch == 5; /* MTF, MTB */
}

void sb_motor_init(sb_motor_board *b, const sb_hal *hal, const sb_motor_config *cfg)
{
    memset(b, 0, sizeof *b);
    b->hal = hal;
    b->cfg = *cfg;
    b->start_ms = now(b);
    b->commanded_ms = b->start_ms;
    b->watchdog_ms = SB_DEFAULT_WATCHDOG_MS;
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        b->hal->set_motor(b->hal->ctx, ch, 0, false);
    }
}

/* -- the motors ------------------------------------------------------------ */

static int16_t clamp(const sb_motor_board *b, uint8_t ch, int32_t mtps)
{
    int32_t limit = b->cfg.limit_mtps[ch];
    return (int16_t)(mtps > limit ? limit : (mtps < -limit ? -limit : mtps));
}

/* Sets one motor's speed (clamped) and mode; cancels its Move. */
static void set_one(sb_motor_board *b, uint8_t ch, int32_t mtps, uint8_t mode)
{
    b->speed[ch] = clamp(b, ch, mtps);
    b->mode[ch] = mode;
    b->moving_to[ch] = false;
    b->hal->set_motor(b->hal->ctx, ch, b->speed[ch], mode == SB_MODE_BRAKE && !is_lift(ch));
}

/* A speed command's mode: RUN, or IDLE at 0. */
static void run_one(sb_motor_board *b, uint8_t ch, int32_t mtps)
{
    set_one(b, ch, mtps, mtps != 0 ? SB_MODE_RUN : SB_MODE_IDLE);
}

/* Every motor stopped, mode HOLD (e-stop, watchdog). */
static void halt(sb_motor_board *b)
{
    b->commanded_ms = now(b);
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        set_one(b, ch, 0, SB_MODE_HOLD);
    }
}

static bool may_move(const sb_motor_board *b)
{
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        if (b->mode[ch] == SB_MODE_RUN || b->mode[ch] == SB_MODE_MOVE) {
            return true;
        }
    }
    return false;
}

/* -- status ------------------------------------------------------------------ */

/* The whole board's fault (the simulated world failed), 0 when none. */
static uint8_t board_fault(const sb_motor_board *b)
{
    return b->hal->board_fault ? b->hal->board_fault(b->hal->ctx) : SB_FAULT_NONE;
}

static uint8_t fault_code(const sb_motor_board *b)
{
    uint8_t whole = board_fault(b);
    if (whole != SB_FAULT_NONE) return whole;
    if (b->estop) return SB_FAULT_ESTOP;
    if (b->watchdog_tripped) return SB_FAULT_WATCHDOG;
    return b->fault;
}

static sb_msg status(const sb_motor_board *b)
{
    sb_msg s;
    sb_msg_init(&s, SB_STATUS);
    uint8_t flags = b->cfg.simulated ? SB_FLAG_SIMULATED : 0;
    if (b->estop) flags |= SB_FLAG_ESTOP;
    if (b->watchdog_tripped) flags |= SB_FLAG_WATCHDOG;
    if (b->cfg.lockstep) flags |= SB_FLAG_LOCKSTEP;
    if (b->fault != SB_FAULT_NONE || board_fault(b) != SB_FAULT_NONE) flags |= SB_FLAG_FAULT;
    s.body.status.flags = flags;
    s.body.status.fault = fault_code(b);
    s.body.status.watchdog_ms = b->watchdog_ms;
    s.body.status.uptime_ms = since(b, b->start_ms);
    return s;
}

static sb_msg telemetry(const sb_motor_board *b, uint8_t ch)
{
    sb_msg t;
    sb_msg_init(&t, SB_MOTOR_TELEMETRY);
    const sb_hal *h = b->hal;
    uint8_t fault = fault_code(b);
    if (fault == SB_FAULT_NONE && h->motor_fault) {
        fault = h->motor_fault(h->ctx, ch);
    }
    t.body.motor_telemetry.channel = ch;
    t.body.motor_telemetry.mode = b->mode[ch];
    t.body.motor_telemetry.fault = fault;
    t.body.motor_telemetry.speed_mtps = h->encoder_speed(h->ctx, ch);
    t.body.motor_telemetry.turns_mt = h->encoder_turns(h->ctx, ch);
    return t;
}

static sb_msg ack(uint8_t type, sb_ack_result result)
{
    sb_msg a;
    sb_msg_init(&a, SB_ACK);
    a.body.ack.request = type;
    a.body.ack.result = (uint8_t)result;
    return a;
}

/* -- time ---------------------------------------------------------------------- */

void sb_motor_poll(sb_motor_board *b)
{
    const sb_hal *h = b->hal;
    if (h->estop_input && h->estop_input(h->ctx) && !b->estop) {
        b->estop = true;
        halt(b);
    }
    if (b->watchdog_ms && b->armed && !b->watchdog_tripped
        && since(b, b->last_feed) > b->watchdog_ms) {
        b->watchdog_tripped = true;
        halt(b);
    }
    if (b->hold_ms && since(b, b->commanded_ms) > b->hold_ms) {
        bool any = false;
        for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
            if (b->mode[ch] == SB_MODE_RUN) {
                run_one(b, ch, 0); /* the command outlived its hold: stop, latch nothing */
                any = true;
            }
        }
        if (any) {
            b->held_out++;
            b->commanded_ms = now(b);
        }
    }
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        if (!b->moving_to[ch]) continue;
        int32_t turns = h->encoder_turns(h->ctx, ch);
        if ((b->speed[ch] >= 0 && turns >= b->target[ch])
            || (b->speed[ch] < 0 && turns <= b->target[ch])) {
            b->commanded_ms = now(b);
            run_one(b, ch, 0); /* the Move's stop point */
        }
    }
}

/* -- the lease (board_lease.py) ---------------------------------------------------- */

static uint32_t lease_left_ms(const sb_motor_board *b)
{
    if (!b->has_owner) return 0;
    uint32_t span = b->lease_ms > b->watchdog_ms ? b->lease_ms : b->watchdog_ms;
    uint32_t gone = since(b, b->seen_ms);
    return gone < span ? span - gone : 0;
}

bool sb_motor_owns(const sb_motor_board *b, uint8_t session)
{
    return b->has_owner && b->owner == session && lease_left_ms(b) > 0;
}

static sb_msg owner_reply(const sb_motor_board *b, uint8_t result)
{
    sb_msg o;
    sb_msg_init(&o, SB_OWNER);
    uint32_t left = lease_left_ms(b);
    uint32_t cs = left / 10, rest = left % 10; /* nearest, a half to even (Python's round) */
    if (rest > 5 || (rest == 5 && (cs & 1u))) cs++;
    o.body.owner.result = result;
    o.body.owner.session = (left > 0 && b->has_owner) ? b->owner : 0;
    o.body.owner.lease_cs = (uint8_t)(cs > 255 ? 255 : cs);
    o.body.owner.boot = b->cfg.boot;
    return o;
}

static sb_msg claim(sb_motor_board *b, const sb_claim *c, uint8_t session)
{
    bool live = lease_left_ms(b) > 0;
    if (live && (b->owner != session || b->owner_nonce != c->nonce)) {
        return owner_reply(b, SB_CLAIM_HELD);
    }
    if (c->lease_ms == 0) {
        if (!live) return owner_reply(b, SB_CLAIM_FREE);
        b->has_owner = false;
        return owner_reply(b, SB_CLAIM_RELEASED);
    }
    b->has_owner = true;
    b->owner = session;
    b->owner_nonce = c->nonce;
    b->lease_ms = c->lease_ms;
    b->seen_ms = now(b);
    b->armed = true; /* the watchdog counts from the grant */
    b->last_feed = now(b);
    return owner_reply(b, SB_CLAIM_GRANTED);
}

/* What only the lease's holder may send. */
static bool owned(uint8_t type)
{
    switch (type) {
    case SB_SET_WATCHDOG: case SB_CLEAR: case SB_SET_WHEEL_SPEEDS: case SB_SET_LIFT_SPEEDS:
    case SB_RUN: case SB_MOVE: case SB_STEP_TO:
        return true;
    default:
        return false;
    }
}

/* -- messages ------------------------------------------------------------------------- */

/* The replies of one message go out through emit (in order). */
typedef struct {
    sb_writer w;
    bool full;
} reply_out;

static void emit(reply_out *out, const sb_msg *msg)
{
    if (!out->full && sb_writer_add(&out->w, msg) != SB_OK) {
        out->full = true; /* this reply and the rest are left off */
    }
}

static sb_ack_result refusal(const sb_motor_board *b)
{
    if (b->estop) return SB_ACK_ESTOP;
    if (b->watchdog_tripped) return SB_ACK_WATCHDOG;
    return SB_ACK_OK;
}

/* Speeds for the channels of mask (bit n: channel n), as SetWheelSpeeds,
 * SetLiftSpeeds and Run set them. */
static sb_msg speeds(sb_motor_board *b, uint8_t type, const int16_t v[SB_MOTORS], uint8_t mask)
{
    sb_ack_result r = refusal(b);
    if (r != SB_ACK_OK) return ack(type, r);
    b->commanded_ms = now(b);
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        if (((unsigned)mask >> ch) & 1u) run_one(b, ch, v[ch]);
    }
    return ack(type, SB_ACK_OK);
}

static sb_msg move(sb_motor_board *b, const sb_move *mv)
{
    sb_ack_result r = refusal(b);
    if (r != SB_ACK_OK) return ack(SB_MOVE, r);
    uint8_t ch = mv->channel;
    int32_t start = b->hal->encoder_turns(b->hal->ctx, ch);
    int32_t speed = mv->turns_mt >= 0 ? (int32_t)mv->speed_mtps : -(int32_t)mv->speed_mtps;
    b->commanded_ms = now(b);
    set_one(b, ch, speed, SB_MODE_MOVE);
    if (mv->turns_mt == 0) {
        run_one(b, ch, 0);
    } else {
        b->moving_to[ch] = true;
        b->target[ch] = (int32_t)((int64_t)start + mv->turns_mt); /* the counter wraps */
    }
    return ack(SB_MOVE, SB_ACK_OK);
}

static sb_msg stop_or_brake(sb_motor_board *b, uint8_t type, uint8_t mask)
{
    b->commanded_ms = now(b);
    for (uint8_t ch = 0; ch < SB_MOTORS; ch++) {
        if (!(((unsigned)mask >> ch) & 1u)) continue;
        bool brake = type == SB_BRAKE && !is_lift(ch);
        set_one(b, ch, 0, brake ? SB_MODE_BRAKE : SB_MODE_IDLE);
    }
    return ack(type, SB_ACK_OK);
}

static void answer(sb_motor_board *b, const sb_msg *msg, reply_out *out)
{
    const sb_msg_body *m = &msg->body;
    sb_msg r;
    switch (msg->type) {
    case SB_IDENTIFY:
        sb_msg_init(&r, SB_IDENT);
        r.body.ident.board = SB_BOARD_MOTOR;
        r.body.ident.protocol_major = SB_PROTOCOL_MAJOR;
        r.body.ident.protocol_minor = SB_PROTOCOL_MINOR;
        r.body.ident.channels = SB_MOTORS;
        r.body.ident.firmware = SB_FIRMWARE_VERSION;
        r.body.ident.serial = b->cfg.serial;
        emit(out, &r);
        return;
    case SB_HEARTBEAT: case SB_GET_STATUS:
        r = status(b);
        break;
    case SB_SET_WATCHDOG:
        if (m->set_watchdog.timeout_ms == 0 && may_move(b)) {
            r = ack(SB_SET_WATCHDOG, SB_ACK_BAD_VALUE); /* stop the motors first */
            break;
        }
        b->watchdog_ms = m->set_watchdog.timeout_ms;
        b->hold_ms = m->set_watchdog.hold_ms;
        r = status(b);
        break;
    case SB_ESTOP:
        b->estop = true;
        halt(b);
        r = status(b);
        break;
    case SB_CLEAR:
        if (m->clear.mask & SB_CLEAR_ESTOP) b->estop = false;
        if (m->clear.mask & SB_CLEAR_WATCHDOG) b->watchdog_tripped = false;
        if (m->clear.mask & SB_CLEAR_FAULTS) b->fault = SB_FAULT_NONE;
        r = status(b);
        break;
    case SB_READ_ALL: {
        sb_msg tel[SB_MOTORS];
        for (uint8_t ch = 0; ch < SB_MOTORS; ch++) tel[ch] = telemetry(b, ch);
        r = status(b);
        emit(out, &r);
        for (uint8_t ch = 0; ch < SB_MOTORS; ch++) emit(out, &tel[ch]);
        return;
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
    case SB_STEP_TO: {
        uint32_t done = 0;
        if (!b->hal->step_to || !b->hal->step_to(b->hal->ctx, m->time_us.time_us, &done)) {
            r = ack(msg->type, SB_ACK_NOT_SUPPORTED);
            break;
        }
        sb_motor_poll(b); /* the plant moved on: the watchdog, the hold and the Moves */
        sb_msg_init(&r, SB_STEP_DONE);
        r.body.time_us.time_us = done;
        break;
    }
    case SB_GET_TRUTH: {
        sb_plant_truth t;
        if (!b->hal->truth || !b->hal->truth(b->hal->ctx, &t)) {
            r = ack(msg->type, SB_ACK_NOT_SUPPORTED);
            break;
        }
        sb_msg_init(&r, SB_TRUTH);
        r.body.truth.flags = t.fell ? 1u : 0u;
        r.body.truth.max_pitch_cdeg = t.max_pitch_cdeg;
        r.body.truth.offset_mm = t.offset_mm;
        break;
    }
    default:
        r = ack(msg->type, SB_ACK_NOT_SUPPORTED);
        break;
    }
    emit(out, &r);
}

/* One message, checked in the Python fake's order: unknown type, a board's
 * message, Claim, the lease, then the stateless checks and the board's own. */
static void obey(sb_motor_board *b, const sb_msg *msg, uint8_t session, reply_out *out)
{
    sb_msg r;
    b->executed++;
    if (!msg->known) {
        r = ack(msg->type, SB_ACK_UNKNOWN_TYPE);
    } else if (msg->type & SB_TYPE_REPLY) {
        r = ack(msg->type, SB_ACK_NOT_SUPPORTED);
    } else if (msg->type == SB_CLAIM) {
        r = claim(b, &msg->body.claim, session);
    } else if (owned(msg->type) && !sb_motor_owns(b, session)) {
        r = ack(msg->type, SB_ACK_NOT_OWNER);
    } else {
        sb_board_caps caps = SB_MOTOR_BOARD;
        caps.simulation = b->hal->step_to != NULL; /* a board on a simulated plant */
        sb_ack_result c = sb_check_request(&caps, msg);
        if (c == SB_ACK_OK) {
            answer(b, msg, out);
            return;
        }
        r = ack(msg->type, c);
    }
    emit(out, &r);
}

/* A frame of the lease's holder renews the lease and feeds the watchdog. */
static void hear(sb_motor_board *b, uint8_t session)
{
    sb_motor_poll(b); /* a frame that comes too late does not un-trip the watchdog */
    if (sb_motor_owns(b, session)) {
        b->last_feed = now(b);
        b->seen_ms = now(b);
    }
}

static bool same_request(const sb_motor_board *b, const sb_frame *f)
{
    return b->cached && f->session == b->req_session && f->seq == b->req_seq
           && f->msgs_len == b->req_len && memcmp(f->msgs, b->req_msgs, f->msgs_len) == 0;
}

size_t sb_motor_frame(sb_motor_board *b, const sb_frame *f, uint8_t out[SB_MAX_WIRE])
{
    if (f->from_board || f->board != SB_BOARD_MOTOR) {
        return 0;
    }
    b->frames++;
    hear(b, f->session);
    if (same_request(b, f)) {
        b->duplicates++; /* a retry or a line's duplicate: the kept reply, not executed again */
        memcpy(out, b->reply, b->reply_len);
        return b->reply_len;
    }
    uint8_t body[SB_MAX_BODY];
    reply_out ro;
    ro.full = false;
    if (sb_writer_begin(&ro.w, body, sizeof body, SB_BOARD_MOTOR, true, f->session, f->seq)
        != SB_OK) {
        return 0;
    }
    sb_msg_iter it;
    sb_msg msg;
    sb_msg_iter_init(&it, f);
    while (sb_msg_iter_next(&it, &msg)) {
        obey(b, &msg, f->session, &ro);
    }
    b->cut += ro.full ? 1u : 0u;
    size_t body_len = 0, wire_len = 0;
    if (sb_writer_finish(&ro.w, &body_len) != SB_OK
        || sb_wire_encode(body, body_len, b->reply, sizeof b->reply, &wire_len) != SB_OK) {
        return 0;
    }
    b->cached = true;
    b->req_session = f->session;
    b->req_seq = f->seq;
    b->req_len = f->msgs_len;
    memcpy(b->req_msgs, f->msgs, f->msgs_len);
    b->reply_len = wire_len;
    memcpy(out, b->reply, wire_len);
    return wire_len;
}
