/* The motor board (docs/protocol.md, section 3): six motors, one host's
 * lease (Claim/Owner), the watchdog, the command hold, the latched e-stop
 * and Clear, speeds and Moves with their stop points, Status and telemetry,
 * and the duplicate cache of section 5.  No allocation: one sb_motor_board
 * holds all of it.  The Python twin is stairbot/fakes/boards.py (MotorBoard)
 * with board_lease.py and serial_boards.py (the cache). */
#ifndef SB_MOTOR_H
#define SB_MOTOR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sb_frame.h"
#include "sb_hal.h"

#define SB_MOTORS 6
#define SB_FIRMWARE_VERSION 0x0100u
#define SB_DEFAULT_WATCHDOG_MS 250u

/* MotorMode, MotorFault, StatusFlag and ClearMask (section 2, "Codes"). */
enum { SB_MODE_IDLE = 0, SB_MODE_RUN = 1, SB_MODE_MOVE = 2, SB_MODE_BRAKE = 3, SB_MODE_HOLD = 4 };
enum { SB_FAULT_NONE = 0, SB_FAULT_ESTOP = 1, SB_FAULT_WATCHDOG = 2, SB_FAULT_LIMIT = 6 };
enum {
    SB_FLAG_ESTOP = 0x01, SB_FLAG_WATCHDOG = 0x02, SB_FLAG_FAULT = 0x04,
    SB_FLAG_SIMULATED = 0x40, SB_FLAG_LOCKSTEP = 0x80
};
enum { SB_CLEAR_ESTOP = 0x01, SB_CLEAR_WATCHDOG = 0x02, SB_CLEAR_FAULTS = 0x04 };
enum { SB_CLAIM_GRANTED = 0, SB_CLAIM_HELD = 1, SB_CLAIM_RELEASED = 2, SB_CLAIM_FREE = 3 };

typedef struct {
    uint16_t serial;
    uint32_t boot;                   /* drawn at power-up (Owner.boot), not 0 */
    int16_t limit_mtps[SB_MOTORS];   /* each motor's speed limit (> 0) */
    bool simulated;                  /* Status flag SIMULATED: a board on a simulated plant */
    bool lockstep;                   /* Status flag LOCKSTEP: its plant moves only on StepTo */
} sb_motor_config;

typedef struct {
    const sb_hal *hal;
    sb_motor_config cfg;
    uint32_t start_ms;
    /* the watchdog and the command hold */
    uint16_t watchdog_ms;
    uint16_t hold_ms;
    bool armed;        /* a lease was granted: the watchdog counts from last_feed */
    uint32_t last_feed;
    uint32_t commanded_ms; /* the motors' last command */
    uint32_t held_out;     /* motors stopped by the command hold */
    /* latches */
    bool estop;
    bool watchdog_tripped;
    uint8_t fault;
    /* the lease */
    bool has_owner;
    uint8_t owner;
    uint32_t owner_nonce;
    uint16_t lease_ms;
    uint32_t seen_ms;
    /* the motors */
    uint8_t mode[SB_MOTORS];
    int16_t speed[SB_MOTORS]; /* commanded, clamped */
    bool moving_to[SB_MOTORS];
    int32_t target[SB_MOTORS];
    /* the duplicate cache: the last request executed and its reply */
    bool cached;
    uint8_t req_session;
    uint8_t req_seq;
    uint8_t req_len;
    uint8_t req_msgs[SB_MAX_MSG_BYTES];
    uint8_t reply[SB_MAX_WIRE];
    size_t reply_len;
    /* counts */
    uint32_t frames;
    uint32_t duplicates;
    uint32_t executed;   /* messages executed */
    uint32_t cut;        /* reply frames that could not hold every reply */
} sb_motor_board;

/* Power-up: every motor IDLE at speed 0, no lease, watchdog 250 ms (not armed). */
void sb_motor_init(sb_motor_board *b, const sb_hal *hal, const sb_motor_config *cfg);

/* Checks the e-stop input, the watchdog, the command hold and the Moves'
 * stop points at the present time; call it often (every millisecond or so). */
void sb_motor_poll(sb_motor_board *b);

/* Obeys one valid frame (from sb_reader_push or sb_wire_decode) and writes
 * its reply, stuffed and delimited, to out; returns the reply's length, 0
 * for a frame that gets none (another board's, a board's own). */
size_t sb_motor_frame(sb_motor_board *b, const sb_frame *f, uint8_t out[SB_MAX_WIRE]);

/* Whether session holds a live lease. */
bool sb_motor_owns(const sb_motor_board *b, uint8_t session);

#endif
