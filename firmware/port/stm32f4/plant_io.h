/* The plant link's byte stream (sb_plant_io, firmware/plant) on a USART:
 * QEMU's second -serial (USART2), which the simulated world answers. */
#ifndef SB_PLANT_IO_H
#define SB_PLANT_IO_H

#include "sb_plant.h"
#include "uart.h"

sb_plant_io plant_io_on(sb_uart *u);

#endif
