/* The STM32F405's reset: the vector table (the initial stack pointer, then
 * the handlers), .data copied from flash, .bss zeroed, then main.  Written
 * in C: a Cortex-M loads the stack pointer from the table itself, so no
 * assembly is needed.  The symbols come from stm32f405.ld. */
#include <stdint.h>
#include <string.h>

#include "stm32f4.h"

extern uint32_t _estack;
extern uint32_t _sdata, _edata, _sidata, _sbss, _ebss;

int main(void);
void Reset_Handler(void);
void Default_Handler(void);
void SysTick_Handler(void);
void USART1_IRQHandler(void);
void USART2_IRQHandler(void);

/* A fault or an interrupt nobody handles: stop here, where a debugger sees it
 * (the motors are left as the last command set them; a real board's
 * hardware watchdog and its motor drivers' own enable line cover this). */
void Default_Handler(void)
{
    for (;;) {
    }
}

/* Handlers a program does not define fall back to Default_Handler. */
void SysTick_Handler(void) __attribute__((weak, alias("Default_Handler")));
void USART1_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));
void USART2_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));

typedef void (*sb_handler)(void);

typedef struct {
    uint32_t *stack;                  /* the initial stack pointer */
    sb_handler system[15];            /* Reset .. SysTick */
    sb_handler irq[SB_IRQS];          /* the peripherals' */
} sb_vectors;

/* Placed at the start of flash (0x08000000, aliased at 0 at boot). */
__attribute__((section(".isr_vector"), used))
static const sb_vectors vectors = {
    .stack = &_estack,
    .system = {
        Reset_Handler,   /* 1 Reset */
        Default_Handler, /* 2 NMI */
        Default_Handler, /* 3 HardFault */
        Default_Handler, /* 4 MemManage */
        Default_Handler, /* 5 BusFault */
        Default_Handler, /* 6 UsageFault */
        0, 0, 0, 0,      /* 7..10 reserved */
        Default_Handler, /* 11 SVCall */
        Default_Handler, /* 12 DebugMonitor */
        0,               /* 13 reserved */
        Default_Handler, /* 14 PendSV */
        SysTick_Handler, /* 15 SysTick */
    },
    /* Only these are ever enabled; an entry left 0 would end in HardFault. */
    .irq = {
        [IRQ_USART1] = USART1_IRQHandler,
        [IRQ_USART2] = USART2_IRQHandler,
    },
};

void Reset_Handler(void)
{
    size_t data = (size_t)((uintptr_t)&_edata - (uintptr_t)&_sdata);
    size_t bss = (size_t)((uintptr_t)&_ebss - (uintptr_t)&_sbss);
    memcpy(&_sdata, &_sidata, data);
    memset(&_sbss, 0, bss);
    main();
    Default_Handler();
}
