#include "plant_io.h"

#include "clock.h"

#define PLANT_BAUD 1000000u
#define PLANT_TIMEOUT_MS 2000u /* how long the plant's answer is waited for */

static void send(void *ctx, const uint8_t *p, size_t n)
{
    uart_write(ctx, p, n);
}

/* The next byte, sleeping between interrupts until timeout_ms have passed
 * on SysTick's clock. */
static int recv(void *ctx, uint32_t timeout_ms)
{
    sb_uart *u = ctx;
    uint32_t start = clock_ms();
    for (;;) {
        int c = uart_getc(u);
        if (c >= 0) return c;
        if (clock_ms() - start >= timeout_ms) return -1;
        uart_sleep(u);
    }
}

sb_plant_io plant_io_open(sb_uart *line)
{
    sb_plant_io io = {uart_open(line, 2, PLANT_BAUD), send, recv};
    return io;
}

void plant_start(sb_plant *p, const sb_plant_io *io, uint8_t board)
{
    while (!sb_plant_hello(p, io, board, PLANT_TIMEOUT_MS)) {
        /* no plant yet: greet it again */
    }
}

void plant_refresh(sb_plant *p, const sb_board *board, const sb_uart *host, uint32_t *last_ms)
{
    uint32_t now = clock_ms();
    /* in lockstep the plant moves only on StepTo, which asks it itself: only
     * a host frame needs its state (the sensor board's world is stepped
     * through the motor board) */
    bool tick = now != *last_ms && !p->info.lockstep;
    if (tick || uart_ready(host)) {
        *last_ms = now;
        p->flags = sb_board_status(board).body.status.flags;
        sb_plant_query(p);
    }
}
