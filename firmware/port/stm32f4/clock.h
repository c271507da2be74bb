/* The board's clock: SysTick interrupting at 1 kHz on the 168 MHz system
 * clock; milliseconds counted by its interrupt, microseconds read between
 * two of them from its counter. */
#ifndef SB_CLOCK_H
#define SB_CLOCK_H

#include <stdint.h>

void clock_init(void);
/* Milliseconds since clock_init (wrapping at 2^32). */
uint32_t clock_ms(void);
/* Microseconds since clock_init (wrapping at 2^32). */
uint32_t clock_us(void);

#endif
