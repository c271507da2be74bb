/* What a board checks of a request's fields before it acts (docs/protocol.md,
 * section 3, "Unknown input"), independent of its state: the answer is an
 * AckResult, OK when the message may go on to the board's own checks (the
 * lease, the latches, SetWatchdog(0) while a motor moves), which come first
 * for NOT_OWNER (section 3, "One host owns the boards"). */
#ifndef SB_CHECK_H
#define SB_CHECK_H

#include <stdbool.h>
#include <stdint.h>

#include "sb_msg.h"

typedef struct {
    uint8_t motors;     /* 6 on the motor board, 0 on the sensor board */
    uint8_t sensors;    /* 4, or 6 with the side pair, on the sensor board; 0 else */
    uint8_t imu_axes;   /* 2 on the sensor board (answered ABSENT without an IMU) */
    bool simulation;    /* a fake board: answers StepTo and GetTruth */
} sb_board_caps;

extern const sb_board_caps SB_MOTOR_BOARD;
extern const sb_board_caps SB_SENSOR_BOARD;      /* without the side pair */
extern const sb_board_caps SB_SENSOR_BOARD_SIDE; /* with it */

/* UNKNOWN_TYPE (a type the codec does not know), NOT_SUPPORTED (a board's
 * message, a message this board does not have), BAD_CHANNEL (a channel or
 * axis beyond the board's, a Stop/Brake mask above bit 5), BAD_VALUE (a Move
 * at speed 0 or above 32767), else OK. */
sb_ack_result sb_check_request(const sb_board_caps *caps, const sb_msg *msg);

#endif
