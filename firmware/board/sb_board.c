#include "sb_board.h"

#include <string.h>

#include "sb_codec.h"

uint32_t sb_board_now(const sb_board *b)
{
    return b->hal->now_ms(b->hal->ctx);
}

uint32_t sb_board_since(const sb_board *b, uint32_t then)
{
    return (uint32_t)(sb_board_now(b) - then);
}

uint32_t sb_board_now_us(const sb_board *b)
{
    if (b->hal->now_us) return b->hal->now_us(b->hal->ctx);
    return sb_board_now(b) * 1000u; /* wraps as the microsecond clock does */
}

void sb_board_init(sb_board *b, const sb_hal *hal, const sb_board_ops *ops,
                   const sb_board_id *id, const sb_board_caps *caps)
{
    memset(b, 0, sizeof *b);
    b->hal = hal;
    b->ops = ops;
    b->id = *id;
    b->caps = *caps;
    b->start_ms = sb_board_now(b);
    b->watchdog_ms = SB_DEFAULT_WATCHDOG_MS;
}

static void halt(sb_board *b)
{
    if (b->ops->halt) b->ops->halt(b);
}

/* -- status ------------------------------------------------------------------ */

/* The whole board's fault (the simulated world failed), 0 when none. */
static uint8_t board_fault(const sb_board *b)
{
    return b->hal->board_fault ? b->hal->board_fault(b->hal->ctx) : SB_FAULT_NONE;
}

uint8_t sb_board_latch(const sb_board *b)
{
    uint8_t whole = board_fault(b);
    if (whole != SB_FAULT_NONE) return whole;
    if (b->estop) return SB_FAULT_ESTOP;
    if (b->watchdog_tripped) return SB_FAULT_WATCHDOG;
    return SB_FAULT_NONE;
}

uint8_t sb_board_fault_code(const sb_board *b)
{
    uint8_t latch = sb_board_latch(b);
    return latch != SB_FAULT_NONE ? latch : b->fault;
}

sb_msg sb_board_status(const sb_board *b)
{
    sb_msg s;
    sb_msg_init(&s, SB_STATUS);
    uint8_t flags = b->id.simulated ? SB_FLAG_SIMULATED : 0;
    if (b->estop) flags |= SB_FLAG_ESTOP;
    if (b->watchdog_tripped) flags |= SB_FLAG_WATCHDOG;
    if (b->id.lockstep) flags |= SB_FLAG_LOCKSTEP;
    if (b->fault != SB_FAULT_NONE || board_fault(b) != SB_FAULT_NONE) flags |= SB_FLAG_FAULT;
    s.body.status.flags = flags;
    s.body.status.fault = sb_board_fault_code(b);
    s.body.status.watchdog_ms = b->watchdog_ms;
    s.body.status.uptime_ms = sb_board_since(b, b->start_ms);
    return s;
}

sb_msg sb_board_ack(uint8_t type, sb_ack_result result)
{
    sb_msg a;
    sb_msg_init(&a, SB_ACK);
    a.body.ack.request = type;
    a.body.ack.result = (uint8_t)result;
    return a;
}

sb_ack_result sb_board_refusal(const sb_board *b)
{
    if (b->estop) return SB_ACK_ESTOP;
    if (b->watchdog_tripped) return SB_ACK_WATCHDOG;
    return SB_ACK_OK;
}

void sb_board_emit(sb_reply *out, const sb_msg *msg)
{
    if (!out->full && sb_writer_add(&out->w, msg) != SB_OK) {
        out->full = true; /* this reply and the rest are left off */
    }
}

/* -- time ---------------------------------------------------------------------- */

void sb_board_poll(sb_board *b)
{
    const sb_hal *h = b->hal;
    if (h->estop_input && h->estop_input(h->ctx) && !b->estop) {
        b->estop = true;
        halt(b);
    }
    if (b->watchdog_ms && b->armed && !b->watchdog_tripped
        && sb_board_since(b, b->last_feed) > b->watchdog_ms) {
        b->watchdog_tripped = true;
        halt(b);
    }
    if (b->ops->poll) b->ops->poll(b);
}

/* -- the lease (board_lease.py) ---------------------------------------------------- */

static uint32_t lease_left_ms(const sb_board *b)
{
    if (!b->has_owner) return 0;
    uint32_t span = b->lease_ms > b->watchdog_ms ? b->lease_ms : b->watchdog_ms;
    uint32_t gone = sb_board_since(b, b->seen_ms);
    return gone < span ? span - gone : 0;
}

bool sb_board_owns(const sb_board *b, uint8_t session)
{
    return b->has_owner && b->owner == session && lease_left_ms(b) > 0;
}

static sb_msg owner_reply(const sb_board *b, uint8_t result)
{
    sb_msg o;
    sb_msg_init(&o, SB_OWNER);
    uint32_t left = lease_left_ms(b);
    uint32_t cs = left / 10, rest = left % 10; /* nearest, a half to even (Python's round) */
    if (rest > 5 || (rest == 5 && (cs & 1u))) cs++;
    o.body.owner.result = result;
    o.body.owner.session = (left > 0 && b->has_owner) ? b->owner : 0;
    o.body.owner.lease_cs = (uint8_t)(cs > 255 ? 255 : cs);
    o.body.owner.boot = b->id.boot;
    return o;
}

static sb_msg claim(sb_board *b, const sb_claim *c, uint8_t session)
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
    b->seen_ms = sb_board_now(b);
    b->armed = true; /* the watchdog counts from the grant */
    b->last_feed = sb_board_now(b);
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

/* The answers every board gives (Board.answer in boards.py). */
static sb_msg common_answer(sb_board *b, const sb_msg *msg)
{
    const sb_msg_body *m = &msg->body;
    sb_msg r;
    switch (msg->type) {
    case SB_IDENTIFY:
        sb_msg_init(&r, SB_IDENT);
        r.body.ident.board = b->id.address;
        r.body.ident.protocol_major = SB_PROTOCOL_MAJOR;
        r.body.ident.protocol_minor = SB_PROTOCOL_MINOR;
        r.body.ident.channels = b->id.channels;
        r.body.ident.firmware = SB_FIRMWARE_VERSION;
        r.body.ident.serial = b->id.serial;
        return r;
    case SB_HEARTBEAT: case SB_GET_STATUS:
        return sb_board_status(b);
    case SB_SET_WATCHDOG:
        if (m->set_watchdog.timeout_ms == 0 && b->ops->may_move && b->ops->may_move(b)) {
            return sb_board_ack(SB_SET_WATCHDOG, SB_ACK_BAD_VALUE); /* stop the motors first */
        }
        b->watchdog_ms = m->set_watchdog.timeout_ms;
        b->hold_ms = m->set_watchdog.hold_ms;
        return sb_board_status(b);
    case SB_ESTOP:
        b->estop = true;
        halt(b);
        return sb_board_status(b);
    case SB_CLEAR:
        if (m->clear.mask & SB_CLEAR_ESTOP) b->estop = false;
        if (m->clear.mask & SB_CLEAR_WATCHDOG) b->watchdog_tripped = false;
        if (m->clear.mask & SB_CLEAR_FAULTS) b->fault = SB_FAULT_NONE;
        return sb_board_status(b);
    default:
        return sb_board_ack(msg->type, SB_ACK_NOT_SUPPORTED);
    }
}

/* One message, checked in the Python fake's order: unknown type, a board's
 * message, Claim, the lease, then the stateless checks and the board's own. */
static void obey(sb_board *b, const sb_msg *msg, uint8_t session, sb_reply *out)
{
    sb_msg r;
    b->executed++;
    if (!msg->known) {
        r = sb_board_ack(msg->type, SB_ACK_UNKNOWN_TYPE);
    } else if (msg->type & SB_TYPE_REPLY) {
        r = sb_board_ack(msg->type, SB_ACK_NOT_SUPPORTED);
    } else if (msg->type == SB_CLAIM) {
        r = claim(b, &msg->body.claim, session);
    } else if (owned(msg->type) && !sb_board_owns(b, session)) {
        r = sb_board_ack(msg->type, SB_ACK_NOT_OWNER);
    } else {
        sb_ack_result c = sb_check_request(&b->caps, msg);
        if (c == SB_ACK_OK && b->ops->answer && b->ops->answer(b, msg, out)) {
            return;
        }
        r = c == SB_ACK_OK ? common_answer(b, msg) : sb_board_ack(msg->type, c);
    }
    sb_board_emit(out, &r);
}

/* A frame of the lease's holder renews the lease and feeds the watchdog. */
static void hear(sb_board *b, uint8_t session)
{
    sb_board_poll(b); /* a frame that comes too late does not un-trip the watchdog */
    if (sb_board_owns(b, session)) {
        b->last_feed = sb_board_now(b);
        b->seen_ms = sb_board_now(b);
    }
}

static bool same_request(const sb_board *b, const sb_frame *f)
{
    return b->cached && f->session == b->req_session && f->seq == b->req_seq
           && f->msgs_len == b->req_len && memcmp(f->msgs, b->req_msgs, f->msgs_len) == 0;
}

size_t sb_board_frame(sb_board *b, const sb_frame *f, uint8_t out[SB_MAX_WIRE])
{
    if (f->from_board || f->board != b->id.address) {
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
    sb_reply ro;
    ro.full = false;
    if (sb_writer_begin(&ro.w, body, sizeof body, b->id.address, true, f->session, f->seq)
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
