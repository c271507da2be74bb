/* The sensor board (docs/protocol.md, section 3): four range sensors, six
 * with the side pair, and the IMU's pitch and roll, on top of what every
 * board does (sb_board.h: the lease, the watchdog, the latches, Status and
 * the duplicate cache).  It drives no motors: its watchdog and e-stop latch
 * and stop nothing, and SetWatchdog(0) is always allowed.  ReadAll answers
 * Status, each channel's SensorTelemetry and the IMU's two ImuTelemetry;
 * GetSensor and GetImu one of them.  Telemetry comes from the HAL's
 * range_read and imu_read with each value's age (now_us minus its
 * measurement's time, nearest ms, saturating at 65535) and, per channel, a
 * count of new measurements.  No allocation: one sb_sensor_board holds all
 * of it.  The Python twin is stairbot/fakes/boards.py (SensorBoard). */
#ifndef SB_SENSOR_H
#define SB_SENSOR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sb_board.h"

#define SB_SENSOR_CHANNELS 4     /* SFR, SFL, SBR, SBL */
#define SB_SENSOR_CHANNELS_MAX 6 /* with the side pair: SSR, SSL */
#define SB_IMU_AXES 2            /* pitch, roll */
#define SB_AGE_MAX_MS 65535u     /* an age saturates here: "this old or older" */
#define SB_ANGLE_MAX_CDEG 18000  /* an IMU angle lies within +-180.00 degrees */

/* SensorCode and ImuCode (section 2, "Codes"). */
enum { SB_SENSOR_OK = 0, SB_SENSOR_OUT_OF_RANGE = 1, SB_SENSOR_ERROR = 2 };
enum { SB_IMU_OK = 0, SB_IMU_ABSENT = 1, SB_IMU_ERROR = 2 };

typedef struct {
    uint16_t serial;
    uint32_t boot;    /* drawn at power-up (Owner.boot), not 0 */
    uint8_t channels; /* 4, or 6 with the side pair (anything else: 4) */
    bool simulated;   /* Status flag SIMULATED: a board on a simulated plant */
    bool lockstep;    /* Status flag LOCKSTEP: its plant moves only on StepTo */
} sb_sensor_config;

/* What the board remembers of one channel's or axis's measurements. */
typedef struct {
    bool seen;           /* a measurement has been read */
    uint32_t measured_us; /* the last one's time */
    uint32_t new_ms;     /* when (board time) it was first read: its age is at least since then */
    uint16_t sample;     /* new measurements read (SensorTelemetry.sample, wrapping) */
} sb_sensor_seen;

typedef struct {
    sb_board base; /* first: the lease, the latches, the cache and the counts (sb_board.h) */
    sb_sensor_seen range[SB_SENSOR_CHANNELS_MAX];
    sb_sensor_seen imu[SB_IMU_AXES];
} sb_sensor_board;

/* Power-up: no lease, watchdog 250 ms (not armed), no sample counted. */
void sb_sensor_init(sb_sensor_board *b, const sb_hal *hal, const sb_sensor_config *cfg);

/* Checks the e-stop input and the watchdog at the present time; call it
 * often (every millisecond or so). */
void sb_sensor_poll(sb_sensor_board *b);

/* Obeys one valid frame (from sb_reader_push or sb_wire_decode) and writes
 * its reply, stuffed and delimited, to out; returns the reply's length, 0
 * for a frame that gets none (another board's, a board's own). */
size_t sb_sensor_frame(sb_sensor_board *b, const sb_frame *f, uint8_t out[SB_MAX_WIRE]);

/* Whether session holds a live lease. */
bool sb_sensor_owns(const sb_sensor_board *b, uint8_t session);

#endif
