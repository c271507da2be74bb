/* The plant link: a board's motors and sensors provided by a simulated
 * plant (the host's pymunk world, stairbot/fakes/plant_link.py) over a
 * byte stream of its own -- a socket on Linux, a second USART in QEMU.
 * firmware/README.md, "The plant link", gives its frames.
 *
 * The board asks, the plant answers: sb_plant_hello once, then
 * sb_plant_query before the board handles a host frame and every
 * millisecond or so between frames; the HAL (sb_plant_hal) reads what the
 * last answer said, and sends the motors' commands as the board sets them.
 * The plant's clock is the board's: in lockstep the plant moves only on
 * StepTo, which the board hands on (step_to). */
#ifndef SB_PLANT_H
#define SB_PLANT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sb_hal.h"

#define SB_PLANT_MOTORS 6
#define SB_PLANT_SENSORS 6 /* at most: 4, or 6 with the side pair */
#define SB_PLANT_AXES 2
#define SB_PLANT_FAULT_SIMULATION 8 /* MotorFault SIMULATION */

/* The byte stream to the plant. */
typedef struct {
    void *ctx;
    /* Sends n bytes, blocking until they are queued. */
    void (*send)(void *ctx, const uint8_t *p, size_t n);
    /* The next byte received, or -1 when none comes within timeout_ms. */
    int (*recv)(void *ctx, uint32_t timeout_ms);
} sb_plant_io;

/* What the plant says at hello: the board it serves and how. */
typedef struct {
    uint8_t board;      /* 1 motor, 2 sensor */
    uint16_t serial;    /* the board's serial number */
    bool lockstep;      /* the plant moves only on StepTo */
    uint8_t channels;   /* motors, or range channels (4, or 6 with the side pair) */
    int16_t limit_mtps[SB_PLANT_MOTORS]; /* each motor's speed limit (motor board) */
} sb_plant_info;

typedef struct {
    int32_t turns_mt;
    int16_t speed_mtps;
    uint8_t fault;      /* MotorFault: 0 NONE, 6 LIMIT, 7 DRIVER */
} sb_plant_motor;

typedef struct {
    bool measured;      /* false: never measured */
    sb_range r;
} sb_plant_range;

typedef struct {
    const sb_plant_io *io;
    uint32_t timeout_ms; /* how long an answer is waited for */
    sb_plant_info info;
    /* the last answer */
    uint64_t now_us;
    bool failed;         /* the simulated world failed (a fall): the board's SIMULATION fault */
    sb_plant_motor motor[SB_PLANT_MOTORS];
    sb_plant_range range[SB_PLANT_SENSORS];
    bool imu_fitted;
    sb_imu_sample imu[SB_PLANT_AXES];
    volatile bool estop_pressed; /* the board's e-stop button (the port sets it) */
    uint8_t flags;       /* the board's Status.flags, sent with each query (the port keeps it) */
    uint8_t seq;         /* the last request's */
    /* counts */
    uint32_t queries;
    uint32_t lost;       /* answers that did not come, or came malformed */
} sb_plant;

/* Greets the plant as board (1 motor, 2 sensor) and reads its first state;
 * false when the plant does not answer within timeout_ms. */
bool sb_plant_hello(sb_plant *p, const sb_plant_io *io, uint8_t board, uint32_t timeout_ms);

/* Asks the plant for its state now, telling it the board's flags; false
 * (the last state kept, counted in lost) when no answer comes. */
bool sb_plant_query(sb_plant *p);

/* The HAL on this plant: now_ms/now_us are the plant's time at the last
 * answer; set_motor sends the command at once. */
sb_hal sb_plant_hal(sb_plant *p);

#endif
