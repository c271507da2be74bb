#include "clock.h"

#include "stm32f4.h"

#define TICK_CYCLES (SB_SYSCLK_HZ / 1000u)

static volatile uint32_t ticks;

void SysTick_Handler(void)
{
    ticks++;
}

void clock_init(void)
{
    ticks = 0;
    SYST_RVR = TICK_CYCLES - 1u;
    SYST_CVR = 0;
    SYST_CSR = SYST_CSR_CLKSOURCE | SYST_CSR_TICKINT | SYST_CSR_ENABLE;
}

uint32_t clock_ms(void)
{
    return ticks;
}

uint32_t clock_us(void)
{
    /* The counter counts down from TICK_CYCLES - 1 within each millisecond;
     * read again if the millisecond moved on meanwhile.  Called with
     * interrupts enabled, so a tick is never pending for long. */
    uint32_t ms, left;
    do {
        ms = ticks;
        left = SYST_CVR;
    } while (ms != ticks);
    uint32_t cycles = TICK_CYCLES - 1u - left;
    return ms * 1000u + cycles / (SB_SYSCLK_HZ / 1000000u);
}
