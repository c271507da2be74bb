#include "uart.h"

#include "stm32f4.h"

static sb_uart *volatile usart1, *volatile usart2; /* what the interrupts fill */

/* Pins pin_a and pin_b of port A to alternate function 7 (the USARTs'). */
static void pins_af7(uint32_t pin_a, uint32_t pin_b)
{
    RCC_AHB1ENR |= RCC_AHB1ENR_GPIOA;
    const uint32_t pins[2] = {pin_a, pin_b};
    for (unsigned i = 0; i < 2; i++) {
        uint32_t pin = pins[i];
        GPIOA_MODER = (GPIOA_MODER & ~(3u << (2u * pin))) | (2u << (2u * pin));
        if (pin < 8u) {
            GPIOA_AFRL = (GPIOA_AFRL & ~(0xFu << (4u * pin))) | (7u << (4u * pin));
        } else {
            GPIOA_AFRH = (GPIOA_AFRH & ~(0xFu << (4u * (pin - 8u)))) | (7u << (4u * (pin - 8u)));
        }
    }
}

sb_uart *uart_open(sb_uart *u, unsigned n, uint32_t baud)
{
    uint32_t clock, irq;
    u->head = u->tail = u->dropped = 0;
    if (n == 1) {
        RCC_APB2ENR |= RCC_APB2ENR_USART1;
        pins_af7(9, 10);
        u->base = USART1_BASE;
        usart1 = u;
        clock = SB_APB2_HZ;
        irq = IRQ_USART1;
    } else if (n == 2) {
        RCC_APB1ENR |= RCC_APB1ENR_USART2;
        pins_af7(2, 3);
        u->base = USART2_BASE;
        usart2 = u;
        clock = SB_APB1_HZ;
        irq = IRQ_USART2;
    } else {
        return NULL;
    }
    USART_BRR(u->base) = (clock + baud / 2u) / baud; /* 16x oversampling: mantissa.fraction */
    USART_CR1(u->base) = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_RXNEIE;
    sb_irq_enable(irq);
    return u;
}

/* Every byte the USART holds into the ring (reading DR after SR clears
 * RXNE and an overrun). */
static void receive(sb_uart *u)
{
    uint32_t sr;
    while ((sr = USART_SR(u->base)) & (USART_SR_RXNE | USART_SR_ORE)) {
        uint8_t byte = (uint8_t)USART_DR(u->base);
        if (sr & USART_SR_ORE) u->dropped++;
        if (!(sr & USART_SR_RXNE)) continue;
        uint32_t head = u->head;
        if (head - u->tail >= SB_UART_RING) {
            u->dropped++;
            continue;
        }
        u->ring[head % SB_UART_RING] = byte;
        u->head = head + 1u;
    }
}

void USART1_IRQHandler(void)
{
    receive(usart1);
}

void USART2_IRQHandler(void)
{
    receive(usart2);
}

bool uart_ready(const sb_uart *u)
{
    return u->head != u->tail;
}

void uart_sleep(const sb_uart *u)
{
    /* Masked, so that a byte arriving between the check and the sleep
     * leaves its interrupt pending, which WFI wakes on. */
    sb_irq_off();
    if (!uart_ready(u)) sb_wait_for_interrupt();
    sb_irq_on();
}

int uart_getc(sb_uart *u)
{
    uint32_t tail = u->tail;
    if (u->head == tail) return -1;
    uint8_t byte = u->ring[tail % SB_UART_RING];
    u->tail = tail + 1u;
    return byte;
}

void uart_write(sb_uart *u, const uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        while (!(USART_SR(u->base) & USART_SR_TXE)) {
        }
        USART_DR(u->base) = p[i];
    }
}
