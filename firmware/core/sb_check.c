#include "sb_check.h"

const sb_board_caps SB_MOTOR_BOARD = {6, 0, 0, false};
const sb_board_caps SB_SENSOR_BOARD = {0, 4, 2, false};
const sb_board_caps SB_SENSOR_BOARD_SIDE = {0, 6, 2, false};

static sb_ack_result channel(uint8_t ch, uint8_t count)
{
    return ch < count ? SB_ACK_OK : SB_ACK_BAD_CHANNEL;
}

static sb_ack_result motor_request(const sb_board_caps *caps, const sb_msg *msg)
{
    const sb_msg_body *b = &msg->body;
    if (caps->motors == 0) {
        return SB_ACK_NOT_SUPPORTED;
    }
    switch (msg->type) {
    case SB_GET_MOTOR: return channel(b->get_channel.channel, caps->motors);
    case SB_RUN: return channel(b->run.channel, caps->motors);
    case SB_MOVE:
        if (b->move.channel >= caps->motors) {
            return SB_ACK_BAD_CHANNEL;
        }
        return (b->move.speed_mtps == 0 || b->move.speed_mtps > SB_INT16_MAX) ? SB_ACK_BAD_VALUE
                                                                              : SB_ACK_OK;
    case SB_STOP: case SB_BRAKE:
        return (b->motor_mask.mask & ~SB_ALL_MOTORS_MASK) ? SB_ACK_BAD_CHANNEL : SB_ACK_OK;
    default: return SB_ACK_OK; /* SetWheelSpeeds, SetLiftSpeeds: a board clamps speeds */
    }
}

sb_ack_result sb_check_request(const sb_board_caps *caps, const sb_msg *msg)
{
    if (!msg->known) {
        return SB_ACK_UNKNOWN_TYPE;
    }
    if (msg->type & SB_TYPE_REPLY) {
        return SB_ACK_NOT_SUPPORTED;
    }
    switch (msg->type) {
    case SB_GET_MOTOR: case SB_SET_WHEEL_SPEEDS: case SB_SET_LIFT_SPEEDS: case SB_RUN:
    case SB_MOVE: case SB_STOP: case SB_BRAKE:
        return motor_request(caps, msg);
    case SB_GET_SENSOR:
        return caps->sensors ? channel(msg->body.get_channel.channel, caps->sensors)
                             : SB_ACK_NOT_SUPPORTED;
    case SB_GET_IMU:
        return caps->imu_axes ? channel(msg->body.get_imu.axis, caps->imu_axes)
                              : SB_ACK_NOT_SUPPORTED;
    case SB_STEP_TO: case SB_GET_TRUTH:
        return (caps->simulation && caps->motors) ? SB_ACK_OK : SB_ACK_NOT_SUPPORTED;
    default:
        return SB_ACK_OK;
    }
}
