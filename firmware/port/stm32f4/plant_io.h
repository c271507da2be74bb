/* The plant link (firmware/plant) on a USART: its byte stream (sb_plant_io)
 * on QEMU's second -serial (USART2), which the simulated world answers, and
 * when a board image asks it. */
#ifndef SB_PLANT_IO_H
#define SB_PLANT_IO_H

#include "sb_board.h"
#include "sb_plant.h"
#include "uart.h"

/* USART2 at 1 Mbaud into line, and the plant link's byte stream on it. */
sb_plant_io plant_io_open(sb_uart *line);

/* Greets the plant over io as board (SB_BOARD_MOTOR or SB_BOARD_SENSOR)
 * until it answers: the plant may come after the board. */
void plant_start(sb_plant *p, const sb_plant_io *io, uint8_t board);

/* Asks the plant for its state, telling it the board's Status.flags, when
 * a host byte waits on host (so that a frame is handled on the plant's
 * state of now), and, unless the plant is in lockstep, when SysTick's
 * millisecond has moved on since *last_ms. */
void plant_refresh(sb_plant *p, const sb_board *board, const sb_uart *host, uint32_t *last_ms);

#endif
