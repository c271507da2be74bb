/* The motor board (docs/protocol.md, section 3): six motors on top of what
 * every board does (sb_board.h: the lease, the watchdog, the latches, Status
 * and the duplicate cache): the command hold, speeds clamped to each
 * motor's limit, Moves with their stop points, Stop and Brake, ReadAll and
 * GetMotor, and a simulated plant's StepTo and GetTruth.  No allocation:
 * one sb_motor_board holds all of it.  The Python twin is
 * stairbot/fakes/boards.py (MotorBoard). */
#ifndef SB_MOTOR_H
#define SB_MOTOR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sb_board.h"

#define SB_MOTORS 6

/* MotorMode (section 2, "Codes"). */
enum { SB_MODE_IDLE = 0, SB_MODE_RUN = 1, SB_MODE_MOVE = 2, SB_MODE_BRAKE = 3, SB_MODE_HOLD = 4 };

typedef struct {
    uint16_t serial;
    uint32_t boot;                   /* drawn at power-up (Owner.boot), not 0 */
    int16_t limit_mtps[SB_MOTORS];   /* each motor's speed limit (> 0) */
    bool simulated;                  /* Status flag SIMULATED: a board on a simulated plant */
    bool lockstep;                   /* Status flag LOCKSTEP: its plant moves only on StepTo */
} sb_motor_config;

typedef struct {
    sb_board base; /* first: the lease, the latches, the cache and the counts (sb_board.h) */
    int16_t limit_mtps[SB_MOTORS];
    uint32_t commanded_ms; /* the host's last obeyed motion command (the command hold counts from it) */
    uint32_t held_out;     /* motors stopped by the command hold */
    uint8_t mode[SB_MOTORS];
    int16_t speed[SB_MOTORS]; /* commanded, clamped */
    bool moving_to[SB_MOTORS];
    int32_t target[SB_MOTORS];
    uint8_t latched[SB_MOTORS]; /* each motor's latched fault (section 3, "Faults"; 0: none) */
} sb_motor_board;

/* Power-up: every motor IDLE at speed 0, no lease, watchdog 250 ms (not armed). */
void sb_motor_init(sb_motor_board *b, const sb_hal *hal, const sb_motor_config *cfg);

/* Checks the e-stop input, the watchdog, the motors' faults (latching
 * OVERCURRENT, STALL, ENCODER and DRIVER), the command hold and the Moves'
 * stop points at the present time; call it often (every millisecond or so). */
void sb_motor_poll(sb_motor_board *b);

/* Obeys one valid frame (from sb_reader_push or sb_wire_decode) and writes
 * its reply, stuffed and delimited, to out; returns the reply's length, 0
 * for a frame that gets none (another board's, a board's own). */
size_t sb_motor_frame(sb_motor_board *b, const sb_frame *f, uint8_t out[SB_MAX_WIRE]);

/* Whether session holds a live lease. */
bool sb_motor_owns(const sb_motor_board *b, uint8_t session);

#endif
