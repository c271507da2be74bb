/* The boards' hardware abstraction: what sb_motor.c and sb_sensor.c ask of
 * the hardware, and nothing else.  A port fills one sb_hal with the
 * functions its board uses (a motor board leaves the range and IMU ones
 * NULL, a sensor board the motor ones); ctx is handed back to each.  Every
 * call is quick and never blocks, except step_to and truth (a simulated
 * plant's, which wait on the plant's answer). */
#ifndef SB_HAL_H
#define SB_HAL_H

#include <stdbool.h>
#include <stdint.h>

/* One range sensor's latest measurement (section 2, SensorTelemetry). */
typedef struct {
    uint8_t code;         /* SensorCode: 0 OK, 1 OUT_OF_RANGE, 2 ERROR */
    uint16_t distance_mm; /* meaningful with OK only */
    uint32_t measured_us; /* when it was measured, on now_us's clock */
} sb_range;

/* One IMU axis's latest sample (section 2, ImuTelemetry). */
typedef struct {
    uint8_t code;         /* ImuCode: 0 OK, 2 ERROR (ABSENT: imu_read returns false) */
    int16_t angle_cdeg;   /* hundredths of a degree, meaningful with OK only */
    int16_t rate_ddps;    /* tenths of a degree per second */
    uint32_t measured_us; /* when it was sampled, on now_us's clock */
} sb_imu_sample;

/* What GetTruth answers (a simulated plant's own truth). */
typedef struct {
    bool fell;
    int16_t max_pitch_cdeg;
    int32_t offset_mm;
} sb_plant_truth;

typedef struct {
    void *ctx;
    /* Milliseconds since power-up (wrapping at 2^32). */
    uint32_t (*now_ms)(void *ctx);
    /* Microseconds since power-up (wrapping at 2^32), the clock of the
     * measurements' times; NULL: now_ms * 1000. */
    uint32_t (*now_us)(void *ctx);
    /* A fault of the whole board, as a MotorFault code (0: none; 8
     * SIMULATION: the simulated world behind the board failed): FAULT and
     * Status.fault while it lasts.  NULL: none. */
    uint8_t (*board_fault)(void *ctx);

    /* -- the motor board ---------------------------------------------------- */
    /* Drive channel ch at speed_mtps (milli-turns/s, section 1's signs;
     * already clamped to the channel's limit).  brake: speed 0 with the
     * wheel braked actively rather than left to coast (a lift holds at 0
     * either way). */
    void (*set_motor)(void *ctx, uint8_t ch, int16_t speed_mtps, bool brake);
    /* The encoder of channel ch: turns since power-up (milli-turns) and
     * the measured speed (milli-turns/s). */
    int32_t (*encoder_turns)(void *ctx, uint8_t ch);
    int16_t (*encoder_speed)(void *ctx, uint8_t ch);
    /* The motor's own fault (MotorFault: 0 NONE, 6 LIMIT, 7 DRIVER, ...);
     * reported in its telemetry, not latched. */
    uint8_t (*motor_fault)(void *ctx, uint8_t ch);
    /* Whether the board's e-stop input (a button) is pressed; NULL: none. */
    bool (*estop_input)(void *ctx);

    /* -- the sensor board --------------------------------------------------- */
    /* Range channel ch's latest measurement in *out; false: it has never
     * measured (sent as ERROR, its age saturated). */
    bool (*range_read)(void *ctx, uint8_t ch, sb_range *out);
    /* IMU axis (0 pitch, 1 roll)'s latest sample in *out; false: no IMU
     * fitted (sent as ABSENT).  NULL: no IMU. */
    bool (*imu_read)(void *ctx, uint8_t axis, sb_imu_sample *out);

    /* -- a simulated plant (section 6's StepTo and GetTruth); NULL on a real
     * board, which answers both NOT_SUPPORTED ----------------------------- */
    /* Advance the plant to time_us (the host's clock, section 6) and return
     * the plant's time then in *done_us; false: the plant is not in lockstep
     * (answered NOT_SUPPORTED) or did not answer. */
    bool (*step_to)(void *ctx, uint32_t time_us, uint32_t *done_us);
    /* The plant's truth in *out; false: none. */
    bool (*truth)(void *ctx, sb_plant_truth *out);
} sb_hal;

#endif
