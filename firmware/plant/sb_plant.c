#include "sb_plant.h"

#include <string.h>

#include "sb_cobs.h"
#include "sb_crc.h"

/* Frame kinds (firmware/README.md, "The plant link"): the board's requests
 * in capitals, the plant's answers in small letters. */
enum {
    K_HELLO = 'H', K_QUERY = 'Q', K_MOTOR = 'M', K_STEP = 'S', K_TRUTH = 'T',
    K_INFO = 'h', K_MOTOR_STATE = 'm', K_SENSOR_STATE = 'n', K_STEPPED = 's', K_TRUTH_IS = 't'
};

#define BODY_MAX 128
#define WIRE_MAX (BODY_MAX + BODY_MAX / 254 + 2)
#define AXIS_BYTES 9
#define RANGE_BYTES 8
#define MOTOR_BYTES 7

/* -- little-endian fields ------------------------------------------------------------ */

static void put16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

static void put32(uint8_t *p, uint32_t v)
{
    put16(p, (uint16_t)v);
    put16(p + 2, (uint16_t)(v >> 16));
}

static uint16_t get16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

static uint32_t get32(const uint8_t *p)
{
    return (uint32_t)get16(p) | ((uint32_t)get16(p + 2) << 16);
}

static uint64_t get64(const uint8_t *p)
{
    return (uint64_t)get32(p) | ((uint64_t)get32(p + 4) << 32);
}

/* -- frames --------------------------------------------------------------------------- */

/* Sends body[0..n) (kind, seq, fields) with its CRC (big-endian, as the
 * host wire's), stuffed and delimited; body has room for the CRC. */
static void send_body(sb_plant *p, uint8_t *body, size_t n)
{
    uint16_t crc = sb_crc16(body, n);
    body[n] = (uint8_t)(crc >> 8);
    body[n + 1] = (uint8_t)crc;
    uint8_t wire[WIRE_MAX];
    size_t len = 0;
    if (sb_cobs_encode(body, n + 2, wire, sizeof wire - 1, &len) != SB_OK) return;
    wire[len++] = 0;
    p->io->send(p->io->ctx, wire, len);
}

/* The body (without its CRC) of the next frame of `kind` answering request
 * `seq`; its length, or 0 when none comes within the timeout.  Frames of
 * another kind or seq (a late answer to a request given up on) and frames
 * failing their CRC are skipped. */
static size_t recv_body(sb_plant *p, uint8_t kind, uint8_t seq, uint8_t body[BODY_MAX])
{
    uint8_t wire[WIRE_MAX];
    size_t n = 0;
    bool overrun = false;
    for (;;) {
        int c = p->io->recv(p->io->ctx, p->timeout_ms);
        if (c < 0) return 0;
        if (c != 0) {
            if (n < sizeof wire) {
                wire[n++] = (uint8_t)c;
            } else {
                overrun = true;
            }
            continue;
        }
        size_t len = 0;
        bool ok = !overrun && n > 0 && sb_cobs_decode(wire, n, body, BODY_MAX, &len) == SB_OK
                  && len >= 4
                  && sb_crc16(body, len - 2) == (uint16_t)((body[len - 2] << 8) | body[len - 1]);
        n = 0;
        overrun = false;
        if (ok && body[0] == kind && body[1] == seq) return len - 2;
    }
}

/* Sends a request of kind with n field bytes (in body + 2) and returns the
 * answer's length (0: none). */
static size_t ask(sb_plant *p, uint8_t kind, uint8_t answer_kind, uint8_t *body, size_t n)
{
    uint8_t seq = ++p->seq;
    body[0] = kind;
    body[1] = seq;
    send_body(p, body, n + 2);
    size_t len = recv_body(p, answer_kind, seq, body);
    if (len == 0) p->lost++;
    return len;
}

/* -- states ---------------------------------------------------------------------------- */

static bool read_motor_state(sb_plant *p, const uint8_t *b, size_t len)
{
    if (len != 2 + 9 + SB_PLANT_MOTORS * MOTOR_BYTES) return false;
    p->now_us = get64(b + 2);
    p->failed = b[10] != 0;
    for (unsigned ch = 0; ch < SB_PLANT_MOTORS; ch++) {
        const uint8_t *m = b + 11 + ch * MOTOR_BYTES;
        p->motor[ch].turns_mt = (int32_t)get32(m);
        p->motor[ch].speed_mtps = (int16_t)get16(m + 4);
        p->motor[ch].fault = m[6];
    }
    return true;
}

static bool read_sensor_state(sb_plant *p, const uint8_t *b, size_t len)
{
    if (len < 12) return false;
    unsigned channels = b[11];
    if (channels > SB_PLANT_SENSORS
        || len != 12 + channels * RANGE_BYTES + 1 + SB_PLANT_AXES * AXIS_BYTES) {
        return false;
    }
    p->now_us = get64(b + 2);
    p->failed = b[10] != 0;
    const uint8_t *r = b + 12;
    for (unsigned ch = 0; ch < SB_PLANT_SENSORS; ch++, r += RANGE_BYTES) {
        if (ch >= channels) {
            p->range[ch].measured = false;
            continue;
        }
        p->range[ch].measured = r[0] != 0;
        p->range[ch].r.code = r[1];
        p->range[ch].r.distance_mm = get16(r + 2);
        p->range[ch].r.measured_us = get32(r + 4);
    }
    r = b + 12 + channels * RANGE_BYTES;
    p->imu_fitted = r[0] != 0;
    r++;
    for (unsigned axis = 0; axis < SB_PLANT_AXES; axis++, r += AXIS_BYTES) {
        p->imu[axis].code = r[0];
        p->imu[axis].angle_cdeg = (int16_t)get16(r + 1);
        p->imu[axis].rate_ddps = (int16_t)get16(r + 3);
        p->imu[axis].measured_us = get32(r + 5);
    }
    return true;
}

bool sb_plant_query(sb_plant *p)
{
    uint8_t body[BODY_MAX];
    bool motor = p->info.board == 1;
    body[2] = p->flags;
    size_t len = ask(p, K_QUERY, motor ? K_MOTOR_STATE : K_SENSOR_STATE, body, 1);
    if (len == 0) return false;
    p->queries++;
    bool ok = motor ? read_motor_state(p, body, len) : read_sensor_state(p, body, len);
    if (!ok) p->lost++;
    return ok;
}

bool sb_plant_hello(sb_plant *p, const sb_plant_io *io, uint8_t board, uint32_t timeout_ms)
{
    memset(p, 0, sizeof *p);
    p->io = io;
    p->timeout_ms = timeout_ms;
    uint8_t body[BODY_MAX];
    body[2] = board;
    size_t len = ask(p, K_HELLO, K_INFO, body, 1);
    if (len != 2 + 5 + 2 * SB_PLANT_MOTORS || body[2] != board) return false;
    p->info.board = board;
    p->info.serial = get16(body + 3);
    p->info.lockstep = body[5] != 0;
    p->info.channels = body[6];
    for (unsigned ch = 0; ch < SB_PLANT_MOTORS; ch++) {
        p->info.limit_mtps[ch] = (int16_t)get16(body + 7 + 2 * ch);
    }
    return sb_plant_query(p);
}

/* -- the HAL ------------------------------------------------------------------------------ */

static uint32_t now_ms(void *ctx)
{
    return (uint32_t)(((const sb_plant *)ctx)->now_us / 1000u);
}

static uint32_t now_us(void *ctx)
{
    return (uint32_t)((const sb_plant *)ctx)->now_us;
}

static uint8_t board_fault(void *ctx)
{
    return ((const sb_plant *)ctx)->failed ? SB_PLANT_FAULT_SIMULATION : 0;
}

static void set_motor(void *ctx, uint8_t ch, int16_t speed_mtps, bool brake)
{
    sb_plant *p = ctx;
    uint8_t body[BODY_MAX] = {K_MOTOR, 0, ch};
    put16(body + 3, (uint16_t)speed_mtps);
    body[5] = brake ? 1u : 0u;
    send_body(p, body, 6);
}

static int32_t encoder_turns(void *ctx, uint8_t ch)
{
    return ((const sb_plant *)ctx)->motor[ch].turns_mt;
}

static int16_t encoder_speed(void *ctx, uint8_t ch)
{
    return ((const sb_plant *)ctx)->motor[ch].speed_mtps;
}

static uint8_t motor_fault(void *ctx, uint8_t ch)
{
    return ((const sb_plant *)ctx)->motor[ch].fault;
}

static bool estop_input(void *ctx)
{
    return ((const sb_plant *)ctx)->estop_pressed;
}

static bool range_read(void *ctx, uint8_t ch, sb_range *out)
{
    const sb_plant *p = ctx;
    if (ch >= SB_PLANT_SENSORS || !p->range[ch].measured) return false;
    *out = p->range[ch].r;
    return true;
}

static bool imu_read(void *ctx, uint8_t axis, sb_imu_sample *out)
{
    const sb_plant *p = ctx;
    if (!p->imu_fitted || axis >= SB_PLANT_AXES) return false;
    *out = p->imu[axis];
    return true;
}

static bool step_to(void *ctx, uint32_t time_us, uint32_t *done_us)
{
    sb_plant *p = ctx;
    uint8_t body[BODY_MAX];
    put32(body + 2, time_us);
    size_t len = ask(p, K_STEP, K_STEPPED, body, 4);
    if (len != 2 + 5 || body[2] == 0) return false;
    *done_us = get32(body + 3);
    sb_plant_query(p); /* the plant's state at its new time */
    return true;
}

static bool truth(void *ctx, sb_plant_truth *out)
{
    sb_plant *p = ctx;
    uint8_t body[BODY_MAX];
    size_t len = ask(p, K_TRUTH, K_TRUTH_IS, body, 0);
    if (len != 2 + 8 || body[2] == 0) return false;
    out->fell = body[3] != 0;
    out->max_pitch_cdeg = (int16_t)get16(body + 4);
    out->offset_mm = (int32_t)get32(body + 6);
    return true;
}

sb_hal sb_plant_hal(sb_plant *p)
{
    sb_hal h;
    memset(&h, 0, sizeof h);
    h.ctx = p;
    h.now_ms = now_ms;
    h.now_us = now_us;
    h.board_fault = board_fault;
    if (p->info.board == 1) {
        h.set_motor = set_motor;
        h.encoder_turns = encoder_turns;
        h.encoder_speed = encoder_speed;
        h.motor_fault = motor_fault;
        h.estop_input = estop_input;
        h.step_to = step_to; /* the simulation's messages go to the motor board */
        h.truth = truth;
    } else {
        h.range_read = range_read;
        h.imu_read = imu_read;
    }
    return h;
}
