/* sb_motor_qemu: the motor board (board/sb_motor.c) on the STM32F405,
 * serving the host's serial protocol on USART1 (QEMU's first -serial),
 * with the trivial plant (native/plant.c) behind its HAL on SysTick's
 * clock.  No e-stop input: QEMU models no GPIO on this machine. */
#include "clock.h"
#include "plant.h"
#include "sb_motor.h"
#include "serve.h"

#ifndef SB_SERIAL
#define SB_SERIAL 1
#endif
#define HOST_BAUD 115200u

static size_t motor_frame(void *board, const sb_frame *f, uint8_t out[SB_MAX_WIRE])
{
    return sb_motor_frame(board, f, out);
}

int main(void)
{
    static plant world;
    static sb_motor_board board;
    static sb_server server;
    clock_init();
    serve_init(&server, uart_open(1, HOST_BAUD));
    plant_init(&world);
    sb_hal hal = plant_hal(&world);
    sb_motor_config cfg = {SB_SERIAL, serve_boot_id(), {0}, true, false};
    plant_limits(cfg.limit_mtps);
    sb_motor_init(&board, &hal, &cfg);
    for (;;) {
        plant_advance(&world, clock_ms());
        sb_motor_poll(&board);
        serve_bytes(&server, motor_frame, &board);
        serve_idle(&server);
    }
}
