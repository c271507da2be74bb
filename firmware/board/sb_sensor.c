#include "sb_sensor.h"

#include <string.h>

#include "sb_codec.h"

/* The sensor board around its common part (the first member). */
static sb_sensor_board *sensor(sb_board *b)
{
    return (sb_sensor_board *)b;
}

/* Microseconds to the nearest millisecond, a half to even (Python's round,
 * as units.age_to_wire rounds), saturating at SB_AGE_MAX_MS. */
static uint16_t age_ms(uint32_t us)
{
    uint32_t ms = us / 1000u, rest = us % 1000u;
    if (rest > 500u || (rest == 500u && (ms & 1u))) ms++;
    return (uint16_t)(ms > SB_AGE_MAX_MS ? SB_AGE_MAX_MS : ms);
}

/* A measurement taken at measured_us, read now: counts it when it is new
 * (its time differs from the last one read) and returns its age.  The
 * microsecond clock wraps every 71.6 minutes; a measurement read unchanged
 * for longer than SB_AGE_MAX_MS of board time is that old at least, so its
 * age saturates whatever its time says. */
static uint16_t read_age(sb_board *b, sb_sensor_seen *s, uint32_t measured_us)
{
    if (!s->seen || s->measured_us != measured_us) {
        s->seen = true;
        s->measured_us = measured_us;
        s->new_ms = sb_board_now(b);
        s->sample = (uint16_t)(s->sample + 1u);
    } else if (sb_board_since(b, s->new_ms) > SB_AGE_MAX_MS) {
        return (uint16_t)SB_AGE_MAX_MS;
    }
    return age_ms((uint32_t)(sb_board_now_us(b) - measured_us));
}

static sb_msg range_telemetry(sb_sensor_board *sb, uint8_t ch)
{
    sb_board *b = &sb->base;
    const sb_hal *h = b->hal;
    sb_msg t;
    sb_msg_init(&t, SB_SENSOR_TELEMETRY);
    sb_sensor_telemetry *st = &t.body.sensor_telemetry;
    st->channel = ch;
    sb_range r;
    if (!h->range_read || !h->range_read(h->ctx, ch, &r)) {
        st->status = SB_SENSOR_ERROR; /* never measured: ERROR, its age saturated */
        st->distance_mm = 0;
        st->age_ms = (uint16_t)SB_AGE_MAX_MS;
    } else {
        st->age_ms = read_age(b, &sb->range[ch], r.measured_us);
        st->status = r.code;
        st->distance_mm = r.distance_mm;
    }
    st->sample = sb->range[ch].sample;
    return t;
}

static sb_msg imu_telemetry(sb_sensor_board *sb, uint8_t axis)
{
    sb_board *b = &sb->base;
    const sb_hal *h = b->hal;
    sb_msg t;
    sb_msg_init(&t, SB_IMU_TELEMETRY);
    sb_imu_telemetry *it = &t.body.imu_telemetry;
    it->axis = axis;
    sb_imu_sample s;
    if (!h->imu_read || !h->imu_read(h->ctx, axis, &s)) {
        it->status = SB_IMU_ABSENT; /* angle, rate and age 0 */
        return t;
    }
    it->age_ms = read_age(b, &sb->imu[axis], s.measured_us);
    if (s.code == SB_IMU_OK && (s.angle_cdeg < -SB_ANGLE_MAX_CDEG || s.angle_cdeg > SB_ANGLE_MAX_CDEG)) {
        s.code = SB_IMU_ERROR; /* an attitude the wire cannot express */
    }
    it->status = s.code;
    if (s.code == SB_IMU_OK) { /* with any other code the angle and rate mean nothing: 0 */
        it->angle_cdeg = s.angle_cdeg;
        it->rate_ddps = s.rate_ddps < -SB_INT16_MAX ? -SB_INT16_MAX : s.rate_ddps; /* never -32768 */
    }
    return t;
}

static bool answer(sb_board *base, const sb_msg *msg, sb_reply *out)
{
    sb_sensor_board *b = sensor(base);
    sb_msg r;
    switch (msg->type) {
    case SB_READ_ALL: { /* the readings first, then the Status before them, as the fake builds them */
        sb_msg tel[SB_SENSOR_CHANNELS_MAX + SB_IMU_AXES];
        uint8_t n = 0;
        for (uint8_t ch = 0; ch < base->id.channels; ch++) tel[n++] = range_telemetry(b, ch);
        for (uint8_t axis = 0; axis < SB_IMU_AXES; axis++) tel[n++] = imu_telemetry(b, axis);
        r = sb_board_status(base);
        sb_board_emit(out, &r);
        for (uint8_t i = 0; i < n; i++) sb_board_emit(out, &tel[i]);
        return true;
    }
    case SB_GET_SENSOR: /* the channel is checked (sb_check_request) */
        r = range_telemetry(b, msg->body.get_channel.channel);
        break;
    case SB_GET_IMU:
        r = imu_telemetry(b, msg->body.get_imu.axis);
        break;
    default:
        return false;
    }
    sb_board_emit(out, &r);
    return true;
}

static const sb_board_ops SENSOR_OPS = {NULL, NULL, NULL, answer};

void sb_sensor_init(sb_sensor_board *b, const sb_hal *hal, const sb_sensor_config *cfg)
{
    memset(b, 0, sizeof *b);
    bool side = cfg->channels == SB_SENSOR_CHANNELS_MAX;
    const sb_board_id id = {SB_BOARD_SENSOR,
                            side ? SB_SENSOR_CHANNELS_MAX : SB_SENSOR_CHANNELS,
                            cfg->serial, cfg->boot, cfg->simulated, cfg->lockstep};
    sb_board_init(&b->base, hal, &SENSOR_OPS, &id, side ? &SB_SENSOR_BOARD_SIDE : &SB_SENSOR_BOARD);
}

void sb_sensor_poll(sb_sensor_board *b)
{
    sb_board_poll(&b->base);
}

size_t sb_sensor_frame(sb_sensor_board *b, const sb_frame *f, uint8_t out[SB_MAX_WIRE])
{
    return sb_board_frame(&b->base, f, out);
}

bool sb_sensor_owns(const sb_sensor_board *b, uint8_t session)
{
    return sb_board_owns(&b->base, session);
}
