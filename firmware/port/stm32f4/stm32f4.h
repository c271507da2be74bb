/* The few STM32F405 registers the port uses (RM0090), and the Cortex-M4's
 * SysTick, NVIC and interrupt controls (ARMv7-M ARM, chapter B3). */
#ifndef STM32F4_H
#define STM32F4_H

#include <stdint.h>

#define SB_REG(addr) (*(volatile uint32_t *)(uintptr_t)(addr))

/* The system clock: 168 MHz (QEMU's netduinoplus2 runs its SysTick on it;
 * a real board sets its PLL up to it first). */
#define SB_SYSCLK_HZ 168000000u
/* The APB clocks behind the USARTs at that system clock. */
#define SB_APB2_HZ 84000000u /* USART1, USART6 */
#define SB_APB1_HZ 42000000u /* USART2..5 */

/* SysTick */
#define SYST_CSR SB_REG(0xE000E010u)
#define SYST_RVR SB_REG(0xE000E014u)
#define SYST_CVR SB_REG(0xE000E018u)
#define SYST_CSR_ENABLE 0x1u
#define SYST_CSR_TICKINT 0x2u
#define SYST_CSR_CLKSOURCE 0x4u /* the processor clock */

/* NVIC: interrupt set-enable, 32 interrupts a register. */
#define NVIC_ISER(n) SB_REG(0xE000E100u + 4u * (n))

/* RCC clock enables */
#define RCC_AHB1ENR SB_REG(0x40023830u)
#define RCC_APB1ENR SB_REG(0x40023840u)
#define RCC_APB2ENR SB_REG(0x40023844u)
#define RCC_AHB1ENR_GPIOA 0x1u
#define RCC_APB1ENR_USART2 (1u << 17)
#define RCC_APB2ENR_USART1 (1u << 4)

/* GPIO port A: USART1 on PA9/PA10, USART2 on PA2/PA3 (alternate function 7). */
#define GPIOA_MODER SB_REG(0x40020000u)
#define GPIOA_AFRL SB_REG(0x40020020u)
#define GPIOA_AFRH SB_REG(0x40020024u)

/* A USART's registers, from its base address. */
#define USART1_BASE 0x40011000u
#define USART2_BASE 0x40004400u
#define USART_SR(base) SB_REG((base) + 0x00u)
#define USART_DR(base) SB_REG((base) + 0x04u)
#define USART_BRR(base) SB_REG((base) + 0x08u)
#define USART_CR1(base) SB_REG((base) + 0x0Cu)
#define USART_SR_ORE (1u << 3)
#define USART_SR_RXNE (1u << 5)
#define USART_SR_TXE (1u << 7)
#define USART_CR1_RE (1u << 2)
#define USART_CR1_TE (1u << 3)
#define USART_CR1_RXNEIE (1u << 5)
#define USART_CR1_UE (1u << 13)

/* Interrupt numbers (the vector table's entries after the 16 system ones). */
#define IRQ_USART1 37u
#define IRQ_USART2 38u
#define SB_IRQS 82u /* the STM32F405's, up to FPU (81) */

static inline void sb_irq_enable(uint32_t irq)
{
    NVIC_ISER(irq / 32u) = 1u << (irq % 32u);
}

static inline void sb_irq_off(void)
{
    __asm__ volatile("cpsid i" ::: "memory");
}

static inline void sb_irq_on(void)
{
    __asm__ volatile("cpsie i" ::: "memory");
}

/* Sleeps until an interrupt is pending (it wakes with interrupts masked too). */
static inline void sb_wait_for_interrupt(void)
{
    __asm__ volatile("wfi" ::: "memory");
}

#endif
