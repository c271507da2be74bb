#include "sb_codec.h"

#include <string.h>

/* How a field sits on the wire (all little-endian) and in its struct. */
typedef enum {
    K_NONE = 0, /* end of the field list */
    K_U8,
    K_LO4, /* bits 0-3 of a byte, a uint8_t in the struct */
    K_HI4, /* bits 4-7 of the same byte */
    K_I16,
    K_U16,
    K_I32,
    K_U32,
    K_PAD, /* a reserved byte: zero on the wire, no struct field */
} kind;

typedef struct {
    uint8_t kind;
    uint8_t at;     /* byte offset in the payload */
    uint8_t offset; /* byte offset in sb_msg_body */
} field;

typedef struct {
    uint8_t type;
    uint8_t size;
    bool simulation;
    const char *name;
    field fields[SB_MAX_FIELDS];
} layout;

#define F(k, at, member) {(k), (at), (uint8_t)offsetof(sb_msg_body, member)}
#define PAD(at) {K_PAD, (at), 0}

/* docs/protocol.md, section 2; records.py's FORMAT strings. */
static const layout LAYOUTS[] = {
    {SB_IDENTIFY, 0, false, "Identify", {{0}}},
    {SB_HEARTBEAT, 1, false, "Heartbeat", {F(K_U8, 0, heartbeat.counter)}},
    {SB_GET_STATUS, 0, false, "GetStatus", {{0}}},
    {SB_SET_WATCHDOG, 4, false, "SetWatchdog",
     {F(K_U16, 0, set_watchdog.timeout_ms), F(K_U16, 2, set_watchdog.hold_ms)}},
    {SB_ESTOP, 0, false, "EStop", {{0}}},
    {SB_CLEAR, 1, false, "Clear", {F(K_U8, 0, clear.mask)}},
    {SB_CLAIM, 6, false, "Claim", {F(K_U16, 0, claim.lease_ms), F(K_U32, 2, claim.nonce)}},
    {SB_READ_ALL, 0, false, "ReadAll", {{0}}},
    {SB_GET_MOTOR, 1, false, "GetMotor", {F(K_U8, 0, get_channel.channel)}},
    {SB_GET_SENSOR, 1, false, "GetSensor", {F(K_U8, 0, get_channel.channel)}},
    {SB_GET_IMU, 1, false, "GetImu", {F(K_U8, 0, get_imu.axis)}},
    {SB_SET_WHEEL_SPEEDS, 8, false, "SetWheelSpeeds",
     {F(K_I16, 0, wheel_speeds.mwf), F(K_I16, 2, wheel_speeds.mwb), F(K_I16, 4, wheel_speeds.mwr),
      F(K_I16, 6, wheel_speeds.mwl)}},
    {SB_SET_LIFT_SPEEDS, 4, false, "SetLiftSpeeds",
     {F(K_I16, 0, lift_speeds.mtf), F(K_I16, 2, lift_speeds.mtb)}},
    {SB_RUN, 3, false, "Run", {F(K_U8, 0, run.channel), F(K_I16, 1, run.speed_mtps)}},
    {SB_MOVE, 7, false, "Move",
     {F(K_U8, 0, move.channel), F(K_I32, 1, move.turns_mt), F(K_U16, 5, move.speed_mtps)}},
    {SB_STOP, 1, false, "Stop", {F(K_U8, 0, motor_mask.mask)}},
    {SB_BRAKE, 1, false, "Brake", {F(K_U8, 0, motor_mask.mask)}},
    {SB_GET_TRUTH, 0, true, "GetTruth", {{0}}},
    {SB_STEP_TO, 4, true, "StepTo", {F(K_U32, 0, time_us.time_us)}},
    {SB_IDENT, 8, false, "Ident",
     {F(K_U8, 0, ident.board), F(K_U8, 1, ident.protocol_major), F(K_U8, 2, ident.protocol_minor),
      F(K_U8, 3, ident.channels), F(K_U16, 4, ident.firmware), F(K_U16, 6, ident.serial)}},
    {SB_STATUS, 8, false, "Status",
     {F(K_U8, 0, status.flags), F(K_U8, 1, status.fault), F(K_U16, 2, status.watchdog_ms),
      F(K_U32, 4, status.uptime_ms)}},
    {SB_OWNER, 8, false, "Owner",
     {F(K_U8, 0, owner.result), F(K_U16, 1, owner.session), F(K_U8, 3, owner.lease_cs),
      F(K_U32, 4, owner.boot)}},
    {SB_MOTOR_TELEMETRY, 8, false, "MotorTelemetry",
     {F(K_LO4, 0, motor_telemetry.channel), F(K_HI4, 0, motor_telemetry.mode),
      F(K_U8, 1, motor_telemetry.fault), F(K_I16, 2, motor_telemetry.speed_mtps),
      F(K_I32, 4, motor_telemetry.turns_mt)}},
    {SB_SENSOR_TELEMETRY, 8, false, "SensorTelemetry",
     {F(K_U8, 0, sensor_telemetry.channel), F(K_U8, 1, sensor_telemetry.status),
      F(K_U16, 2, sensor_telemetry.distance_mm), F(K_U16, 4, sensor_telemetry.sample),
      F(K_U16, 6, sensor_telemetry.age_ms)}},
    {SB_IMU_TELEMETRY, 8, false, "ImuTelemetry",
     {F(K_U8, 0, imu_telemetry.axis), F(K_U8, 1, imu_telemetry.status),
      F(K_I16, 2, imu_telemetry.angle_cdeg), F(K_I16, 4, imu_telemetry.rate_ddps),
      F(K_U16, 6, imu_telemetry.age_ms)}},
    {SB_ACK, 2, false, "Ack", {F(K_U8, 0, ack.request), F(K_U8, 1, ack.result)}},
    {SB_TRUTH, 8, true, "Truth",
     {F(K_U8, 0, truth.flags), PAD(1), F(K_I16, 2, truth.max_pitch_cdeg),
      F(K_I32, 4, truth.offset_mm)}},
    {SB_STEP_DONE, 4, true, "StepDone", {F(K_U32, 0, time_us.time_us)}},
};

#define N_LAYOUTS (sizeof LAYOUTS / sizeof LAYOUTS[0])

static const layout *find(uint8_t type)
{
    for (size_t i = 0; i < N_LAYOUTS; i++) {
        if (LAYOUTS[i].type == type) {
            return &LAYOUTS[i];
        }
    }
    return NULL;
}

bool sb_type_known(uint8_t type) { return find(type) != NULL; }

int sb_payload_size(uint8_t type)
{
    const layout *l = find(type);
    return l ? l->size : -1;
}

const char *sb_type_name(uint8_t type)
{
    const layout *l = find(type);
    return l ? l->name : NULL;
}

bool sb_type_simulation(uint8_t type)
{
    const layout *l = find(type);
    return l != NULL && l->simulation;
}

/* ---- one field ------------------------------------------------------------ */

static uint32_t get_le(const uint8_t *p, int n)
{
    uint32_t v = 0;
    for (int i = n - 1; i >= 0; i--) {
        v = (v << 8) | p[i];
    }
    return v;
}

static void put_le(uint8_t *p, uint32_t v, int n)
{
    for (int i = 0; i < n; i++) {
        p[i] = (uint8_t)(v >> (8 * i));
    }
}

/* The struct's value of a field, widened. */
static int64_t load(const sb_msg_body *body, const field *f)
{
    const uint8_t *p = (const uint8_t *)body + f->offset;
    uint8_t u8;
    uint16_t u16;
    int16_t i16;
    uint32_t u32;
    int32_t i32;
    switch (f->kind) {
    case K_U8: case K_LO4: case K_HI4: memcpy(&u8, p, 1); return u8;
    case K_I16: memcpy(&i16, p, 2); return i16;
    case K_U16: memcpy(&u16, p, 2); return u16;
    case K_I32: memcpy(&i32, p, 4); return i32;
    case K_U32: memcpy(&u32, p, 4); return u32;
    default: return 0;
    }
}

/* Whether v fits the field (its C type, and a nibble's 4 bits). */
static bool fits(const field *f, int64_t v)
{
    switch (f->kind) {
    case K_U8: return v >= 0 && v <= UINT8_MAX;
    case K_LO4: case K_HI4: return v >= 0 && v <= 15;
    case K_I16: return v >= INT16_MIN && v <= INT16_MAX;
    case K_U16: return v >= 0 && v <= UINT16_MAX;
    case K_I32: return v >= INT32_MIN && v <= INT32_MAX;
    case K_U32: return v >= 0 && v <= UINT32_MAX;
    default: return false;
    }
}

static void store(sb_msg_body *body, const field *f, int64_t v)
{
    uint8_t *p = (uint8_t *)body + f->offset;
    uint8_t u8 = (uint8_t)v;
    uint16_t u16 = (uint16_t)v;
    int16_t i16 = (int16_t)v;
    uint32_t u32 = (uint32_t)v;
    int32_t i32 = (int32_t)v;
    switch (f->kind) {
    case K_U8: case K_LO4: case K_HI4: memcpy(p, &u8, 1); break;
    case K_I16: memcpy(p, &i16, 2); break;
    case K_U16: memcpy(p, &u16, 2); break;
    case K_I32: memcpy(p, &i32, 4); break;
    case K_U32: memcpy(p, &u32, 4); break;
    default: break;
    }
}

/* ---- the codec ------------------------------------------------------------- */

sb_err sb_msg_decode(uint8_t type, const uint8_t *payload, size_t n, sb_msg *out)
{
    const layout *l = find(type);
    memset(out, 0, sizeof *out);
    out->type = type;
    if (n > SB_MAX_PAYLOAD) {
        return SB_ERR_MSG_LENGTH;
    }
    if (l == NULL) {
        out->body.raw.len = (uint8_t)n;
        memcpy(out->body.raw.payload, payload, n);
        return SB_OK;
    }
    if (n != l->size) {
        return SB_ERR_PAYLOAD_SIZE;
    }
    out->known = true;
    for (int i = 0; i < SB_MAX_FIELDS && l->fields[i].kind != K_NONE; i++) {
        const field *f = &l->fields[i];
        const uint8_t *p = payload + f->at;
        switch (f->kind) {
        case K_PAD:
            if (*p != 0) {
                return SB_ERR_PADDING;
            }
            break;
        case K_U8: store(&out->body, f, *p); break;
        case K_LO4: store(&out->body, f, *p & 0x0F); break;
        case K_HI4: store(&out->body, f, *p >> 4); break;
        case K_I16: store(&out->body, f, (int16_t)get_le(p, 2)); break;
        case K_U16: store(&out->body, f, get_le(p, 2)); break;
        case K_I32: store(&out->body, f, (int32_t)get_le(p, 4)); break;
        case K_U32: store(&out->body, f, get_le(p, 4)); break;
        default: break;
        }
    }
    return SB_OK;
}

sb_err sb_msg_encode(const sb_msg *msg, uint8_t out[SB_MAX_PAYLOAD], size_t *n)
{
    memset(out, 0, SB_MAX_PAYLOAD);
    if (!msg->known) {
        if (msg->body.raw.len > SB_MAX_PAYLOAD) {
            return SB_ERR_RANGE;
        }
        memcpy(out, msg->body.raw.payload, msg->body.raw.len);
        *n = msg->body.raw.len;
        return SB_OK;
    }
    const layout *l = find(msg->type);
    if (l == NULL) {
        return SB_ERR_UNKNOWN_TYPE;
    }
    for (int i = 0; i < SB_MAX_FIELDS && l->fields[i].kind != K_NONE; i++) {
        const field *f = &l->fields[i];
        int64_t v = load(&msg->body, f);
        uint8_t *p = out + f->at;
        switch (f->kind) {
        case K_U8: *p = (uint8_t)v; break;
        case K_LO4: case K_HI4:
            if (!fits(f, v)) {
                return SB_ERR_RANGE;
            }
            *p |= (uint8_t)(f->kind == K_LO4 ? v : v << 4);
            break;
        case K_I16: case K_U16: put_le(p, (uint32_t)v, 2); break;
        case K_I32: case K_U32: put_le(p, (uint32_t)v, 4); break;
        default: break; /* K_PAD: left zero */
        }
    }
    *n = l->size;
    return SB_OK;
}

/* ---- generic field access ---------------------------------------------------- */

/* The i-th field that has a value (reserved bytes skipped). */
static const field *nth(uint8_t type, int i)
{
    const layout *l = find(type);
    if (l == NULL || i < 0) {
        return NULL;
    }
    for (int k = 0; k < SB_MAX_FIELDS && l->fields[k].kind != K_NONE; k++) {
        if (l->fields[k].kind != K_PAD && i-- == 0) {
            return &l->fields[k];
        }
    }
    return NULL;
}

int sb_msg_field_count(uint8_t type)
{
    int count = 0;
    while (nth(type, count) != NULL) {
        count++;
    }
    return find(type) ? count : -1;
}

int64_t sb_msg_field(const sb_msg *msg, int i)
{
    const field *f = msg->known ? nth(msg->type, i) : NULL;
    return f ? load(&msg->body, f) : 0;
}

sb_err sb_msg_init(sb_msg *msg, uint8_t type)
{
    memset(msg, 0, sizeof *msg);
    msg->type = type;
    msg->known = sb_type_known(type);
    return msg->known ? SB_OK : SB_ERR_UNKNOWN_TYPE;
}

sb_err sb_msg_set_field(sb_msg *msg, int i, int64_t value)
{
    const field *f = msg->known ? nth(msg->type, i) : NULL;
    if (f == NULL) {
        return SB_ERR_UNKNOWN_TYPE;
    }
    if (!fits(f, value)) {
        return SB_ERR_RANGE;
    }
    store(&msg->body, f, value);
    return SB_OK;
}
