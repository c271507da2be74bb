#include "serve.h"

#include "stm32f4.h"

/* Left alone by startup.c (section .noinit, first in RAM: 0x20000000), so
 * that what a loader put there before reset is still there. */
__attribute__((section(".noinit"), used)) volatile uint32_t sb_boot_seed;

#define RCC_AHB2ENR SB_REG(0x40023834u)
#define RCC_AHB2ENR_RNG (1u << 6)
#define RNG_CR SB_REG(0x50060800u)
#define RNG_SR SB_REG(0x50060804u)
#define RNG_DR SB_REG(0x50060808u)
#define RNG_CR_RNGEN (1u << 2)
#define RNG_SR_DRDY 0x1u
#define RNG_TRIES 10000u /* a working RNG has a number in 40 of its cycles */

static uint32_t rng(void)
{
    RCC_AHB2ENR |= RCC_AHB2ENR_RNG;
    RNG_CR |= RNG_CR_RNGEN;
    for (uint32_t i = 0; i < RNG_TRIES; i++) {
        if (RNG_SR & RNG_SR_DRDY) return RNG_DR;
    }
    return 0; /* none (QEMU does not model it; nor does a board without its 48 MHz clock) */
}

uint32_t serve_boot_id(void)
{
    uint32_t id = sb_boot_seed;
    if (id == 0) id = rng();
    if (id == 0) id = SYST_CVR * 2654435761u; /* a few bits at best */
    return id ? id : 1u;
}

void serve_init(sb_server *s, sb_uart *uart)
{
    s->uart = uart;
    sb_reader_init(&s->reader);
}

void serve_bytes(sb_server *s, sb_board *board)
{
    int c;
    while ((c = uart_getc(s->uart)) >= 0) {
        sb_frame frame;
        if (!sb_reader_push(&s->reader, (uint8_t)c, &frame)) continue;
        size_t len = sb_board_frame(board, &frame, s->reply);
        if (len > 0) uart_write(s->uart, s->reply, len);
    }
}

