/* USART1 and USART2: bytes received by their interrupt into a ring each,
 * bytes sent by waiting on TXE (QEMU's USART sends at once; on a real board
 * at 1 Mbaud a 255-byte reply holds the loop 2.6 ms, within the protocol's
 * few milliseconds, which DMA would free).  8 data bits, no parity, 1 stop
 * bit. */
#ifndef SB_UART_H
#define SB_UART_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define SB_UART_RING 512u /* a power of 2: two full frames and then some */

typedef struct {
    uint32_t base;
    volatile uint32_t head; /* written by the interrupt */
    volatile uint32_t tail; /* written by the main loop */
    uint8_t ring[SB_UART_RING];
    volatile uint32_t dropped; /* bytes lost to a full ring or the USART's overrun */
} sb_uart;

/* USART n (1: PA9/PA10 on APB2, 2: PA2/PA3 on APB1) at baud into u (which
 * lives as long as the program: its interrupt fills u's ring), its receive
 * interrupt enabled; NULL for another n. */
sb_uart *uart_open(sb_uart *u, unsigned n, uint32_t baud);

/* The next byte received, or -1 when none is waiting. */
int uart_getc(sb_uart *u);
bool uart_ready(const sb_uart *u);
/* Sleeps until an interrupt (a byte on any USART, or SysTick's next
 * millisecond) unless a byte is already waiting on u. */
void uart_sleep(const sb_uart *u);
void uart_write(sb_uart *u, const uint8_t *p, size_t n);

#endif
