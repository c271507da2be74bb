/* What every board image does around its board (board/): the host's frames
 * in from a USART, each answered on it; and the boot id. */
#ifndef SB_SERVE_H
#define SB_SERVE_H

#include <stdint.h>

#include "sb_board.h"
#include "sb_frame.h"
#include "sb_reader.h"
#include "uart.h"

typedef struct {
    sb_uart *uart;
    sb_reader reader;
    uint8_t reply[SB_MAX_WIRE];
} sb_server;

void serve_init(sb_server *s, sb_uart *uart);

/* Every byte waiting, each frame handed to board (sb_board_frame) and its
 * reply sent. */
void serve_bytes(sb_server *s, sb_board *board);

/* The boot id (Owner.boot, never 0): the word a loader wrote at the start of
 * RAM (sb_boot_seed: QEMU's `-device loader,addr=...,data=...`), else the
 * RNG's, else one drawn from SysTick's counter. */
uint32_t serve_boot_id(void);

#endif
