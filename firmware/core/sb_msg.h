/* The boards' messages as typed structs (docs/protocol.md, section 2; the
 * Python twin is stairbot/drivers/records.py and stairbot/fakes/sim_messages.py).
 * Field names and order are records.py's; wire types are the tables'. */
#ifndef SB_MSG_H
#define SB_MSG_H

#include <stdbool.h>
#include <stdint.h>

#define SB_PROTOCOL_MAJOR 5
#define SB_PROTOCOL_MINOR 0
#define SB_MAX_PAYLOAD 8
#define SB_BOARD_MOTOR 1
#define SB_BOARD_SENSOR 2
#define SB_BOARD_BROADCAST 15
#define SB_ALL_MOTORS_MASK 0x3Fu
#define SB_INT16_MAX 32767

typedef enum {
    /* host -> board */
    SB_IDENTIFY = 0x01,
    SB_HEARTBEAT = 0x02,
    SB_GET_STATUS = 0x03,
    SB_SET_WATCHDOG = 0x04,
    SB_ESTOP = 0x05,
    SB_CLEAR = 0x06,
    SB_CLAIM = 0x07,
    SB_READ_ALL = 0x10,
    SB_GET_MOTOR = 0x11,
    SB_GET_SENSOR = 0x12,
    SB_GET_IMU = 0x13,
    SB_SET_WHEEL_SPEEDS = 0x20,
    SB_SET_LIFT_SPEEDS = 0x21,
    SB_RUN = 0x22,
    SB_MOVE = 0x23,
    SB_STOP = 0x24,
    SB_BRAKE = 0x25,
    SB_GET_TRUTH = 0x7D, /* simulation only */
    SB_STEP_TO = 0x7E,   /* simulation only */
    /* board -> host (bit 7 set) */
    SB_IDENT = 0x81,
    SB_STATUS = 0x82,
    SB_OWNER = 0x83,
    SB_MOTOR_TELEMETRY = 0x90,
    SB_SENSOR_TELEMETRY = 0x91,
    SB_IMU_TELEMETRY = 0x92,
    SB_ACK = 0xA0,
    SB_TRUTH = 0xFD,     /* simulation only */
    SB_STEP_DONE = 0xFE, /* simulation only */
} sb_type;

#define SB_TYPE_REPLY 0x80u /* types a board sends */

/* AckResult (docs/protocol.md, section 2, "Codes"). */
typedef enum {
    SB_ACK_OK = 0,
    SB_ACK_ESTOP = 1,
    SB_ACK_WATCHDOG = 2,
    SB_ACK_BAD_CHANNEL = 3,
    SB_ACK_BAD_VALUE = 4,
    SB_ACK_UNKNOWN_TYPE = 5,
    SB_ACK_BAD_LENGTH = 6,
    SB_ACK_NOT_SUPPORTED = 7,
    SB_ACK_NOT_OWNER = 8,
} sb_ack_result;

typedef struct { uint8_t counter; } sb_heartbeat;
typedef struct { uint16_t timeout_ms; uint16_t hold_ms; } sb_set_watchdog;
typedef struct { uint8_t mask; } sb_clear;
typedef struct { uint16_t lease_ms; uint32_t nonce; } sb_claim;
typedef struct { uint8_t channel; } sb_get_channel; /* GetMotor, GetSensor */
typedef struct { uint8_t axis; } sb_get_imu;
typedef struct { int16_t mwf; int16_t mwb; int16_t mwr; int16_t mwl; } sb_wheel_speeds;
typedef struct { int16_t mtf; int16_t mtb; } sb_lift_speeds;
typedef struct { uint8_t channel; int16_t speed_mtps; } sb_run;
typedef struct { uint8_t channel; int32_t turns_mt; uint16_t speed_mtps; } sb_move;
typedef struct { uint8_t mask; } sb_motor_mask; /* Stop, Brake */
typedef struct { uint32_t time_us; } sb_time_us;  /* StepTo, StepDone */
typedef struct {
    uint8_t board;
    uint8_t protocol_major;
    uint8_t protocol_minor;
    uint8_t channels;
    uint16_t firmware;
    uint16_t serial;
} sb_ident;
typedef struct { uint8_t flags; uint8_t fault; uint16_t watchdog_ms; uint32_t uptime_ms; } sb_status;
typedef struct { uint8_t result; uint16_t session; uint8_t lease_cs; uint32_t boot; } sb_owner;
typedef struct {
    uint8_t channel; /* wire: bits 0-3 of byte 0 */
    uint8_t mode;    /* wire: bits 4-7 of byte 0 */
    uint8_t fault;
    int16_t speed_mtps;
    int32_t turns_mt;
} sb_motor_telemetry;
typedef struct {
    uint8_t channel;
    uint8_t status;
    uint16_t distance_mm;
    uint16_t sample;
    uint16_t age_ms;
} sb_sensor_telemetry;
typedef struct {
    uint8_t axis;
    uint8_t status;
    int16_t angle_cdeg;
    int16_t rate_ddps;
    uint16_t age_ms;
} sb_imu_telemetry;
typedef struct { uint8_t request; uint8_t result; } sb_ack;
typedef struct { uint8_t flags; int16_t max_pitch_cdeg; int32_t offset_mm; } sb_truth; /* byte 1 reserved */
typedef struct { uint8_t len; uint8_t payload[SB_MAX_PAYLOAD]; } sb_raw; /* a type the codec does not know */

typedef union {
    sb_heartbeat heartbeat;
    sb_set_watchdog set_watchdog;
    sb_clear clear;
    sb_claim claim;
    sb_get_channel get_channel;
    sb_get_imu get_imu;
    sb_wheel_speeds wheel_speeds;
    sb_lift_speeds lift_speeds;
    sb_run run;
    sb_move move;
    sb_motor_mask motor_mask;
    sb_time_us time_us;
    sb_ident ident;
    sb_status status;
    sb_owner owner;
    sb_motor_telemetry motor_telemetry;
    sb_sensor_telemetry sensor_telemetry;
    sb_imu_telemetry imu_telemetry;
    sb_ack ack;
    sb_truth truth;
    sb_raw raw;
} sb_msg_body;

/* One message: its type code, whether the codec knows the type (else the
 * payload is kept whole in body.raw), and its fields. */
typedef struct {
    uint8_t type;
    bool known;
    sb_msg_body body;
} sb_msg;

#endif
