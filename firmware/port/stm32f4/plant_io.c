#include "plant_io.h"

#include "clock.h"

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

sb_plant_io plant_io_on(sb_uart *u)
{
    sb_plant_io io = {u, send, recv};
    return io;
}
