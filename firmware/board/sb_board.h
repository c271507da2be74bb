/* What both boards of docs/protocol.md (section 3) share: identity, one
 * host's lease (Claim/Owner), the watchdog and its arming, the latched
 * e-stop (message or input) and watchdog, the fault latch and Clear,
 * Status, the answers to Identify, Heartbeat, GetStatus, SetWatchdog,
 * EStop and Clear, the checks every message goes through, and the
 * duplicate cache of section 5 with the frame loop around it.  A board
 * (sb_motor.c, sb_sensor.c) embeds one sb_board as the first member of its
 * own state and adds its messages through sb_board_ops.  The Python twin
 * is Board in stairbot/fakes/boards.py, with board_lease.py and
 * serial_boards.py (the cache). */
#ifndef SB_BOARD_H
#define SB_BOARD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sb_check.h"
#include "sb_frame.h"
#include "sb_hal.h"

#define SB_FIRMWARE_VERSION 0x0100u
#define SB_DEFAULT_WATCHDOG_MS 250u

/* MotorFault, StatusFlag, ClearMask and ClaimResult (section 2, "Codes"). */
enum {
    SB_FAULT_NONE = 0, SB_FAULT_ESTOP = 1, SB_FAULT_WATCHDOG = 2, SB_FAULT_OVERCURRENT = 3,
    SB_FAULT_LIMIT = 6, SB_FAULT_DRIVER = 7
};
enum {
    SB_FLAG_ESTOP = 0x01, SB_FLAG_WATCHDOG = 0x02, SB_FLAG_FAULT = 0x04,
    SB_FLAG_SIMULATED = 0x40, SB_FLAG_LOCKSTEP = 0x80
};
enum { SB_CLEAR_ESTOP = 0x01, SB_CLEAR_WATCHDOG = 0x02, SB_CLEAR_FAULTS = 0x04 };
enum { SB_CLAIM_GRANTED = 0, SB_CLAIM_HELD = 1, SB_CLAIM_RELEASED = 2, SB_CLAIM_FREE = 3 };

/* Who a board is (Ident, Owner.boot, the Status flags SIMULATED and LOCKSTEP). */
typedef struct {
    uint8_t address;  /* SB_BOARD_MOTOR or SB_BOARD_SENSOR */
    uint8_t channels; /* Ident.channels */
    uint16_t serial;
    uint32_t boot;    /* drawn at power-up (Owner.boot), not 0 */
    bool simulated;   /* a board on a simulated plant */
    bool lockstep;    /* its plant moves only on StepTo */
} sb_board_id;

/* The replies of one request go out through sb_board_emit, in order. */
typedef struct {
    sb_writer w;
    bool full; /* a reply did not fit: it and the rest are left off */
} sb_reply;

typedef struct sb_board sb_board;

/* What a board adds to the common part; any of them may be NULL.  Each is
 * handed the sb_board that is the first member of the board's own state. */
typedef struct {
    /* The board's own time checks, after the e-stop input and the watchdog. */
    void (*poll)(sb_board *b);
    /* Stop everything the board drives (the e-stop and the watchdog latch). */
    void (*halt)(sb_board *b);
    /* Whether a motor may be running or moving (SetWatchdog(0) is refused then). */
    bool (*may_move)(const sb_board *b);
    /* Answer a message that passed every check, if it is one of the
     * board's own (true); false leaves it to the common answers. */
    bool (*answer)(sb_board *b, const sb_msg *msg, sb_reply *out);
} sb_board_ops;

struct sb_board {
    const sb_hal *hal;
    const sb_board_ops *ops;
    sb_board_id id;
    sb_board_caps caps; /* what sb_check_request allows */
    uint32_t start_ms;
    /* the watchdog and the command hold (SetWatchdog) */
    uint16_t watchdog_ms;
    uint16_t hold_ms;
    bool armed;        /* a lease was granted: the watchdog counts from last_feed */
    uint32_t last_feed;
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
    uint32_t executed; /* messages executed */
    uint32_t cut;      /* reply frames that could not hold every reply */
};

/* Power-up: no lease, watchdog 250 ms (not armed), no latch. */
void sb_board_init(sb_board *b, const sb_hal *hal, const sb_board_ops *ops,
                   const sb_board_id *id, const sb_board_caps *caps);

/* The e-stop input, the watchdog, then the board's own poll, at the present time. */
void sb_board_poll(sb_board *b);

/* Obeys one valid frame and writes its reply, stuffed and delimited, to
 * out; returns its length, 0 for a frame that gets none (another board's,
 * a board's own). */
size_t sb_board_frame(sb_board *b, const sb_frame *f, uint8_t out[SB_MAX_WIRE]);

/* Whether session holds a live lease. */
bool sb_board_owns(const sb_board *b, uint8_t session);

/* -- for the boards' own messages ----------------------------------------------- */

uint32_t sb_board_now(const sb_board *b);
/* Milliseconds from then to now, wrapping. */
uint32_t sb_board_since(const sb_board *b, uint32_t then);
/* Microseconds since power-up (the HAL's now_us, else now_ms * 1000). */
uint32_t sb_board_now_us(const sb_board *b);
/* The latch every motor reports: the board's whole fault, then ESTOP,
 * WATCHDOG; NONE when none is set. */
uint8_t sb_board_latch(const sb_board *b);
/* Status.fault: sb_board_latch, else the first motor fault latched. */
uint8_t sb_board_fault_code(const sb_board *b);
sb_msg sb_board_status(const sb_board *b);
sb_msg sb_board_ack(uint8_t type, sb_ack_result result);
/* Why a motion command is refused now (OK when it is not). */
sb_ack_result sb_board_refusal(const sb_board *b);
void sb_board_emit(sb_reply *out, const sb_msg *msg);

#endif
