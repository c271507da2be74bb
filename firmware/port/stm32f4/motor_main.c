/* sb_motor_qemu: the motor board (board/sb_motor.c) on the STM32F405,
 * serving the host's serial protocol on USART1 (QEMU's first -serial).
 * Behind its HAL: the trivial plant (native/plant.c) on SysTick's clock;
 * or, built with SB_PLANT_LINK (sb_motor_qemu_link.elf), the simulated
 * robot over the plant link (plant/sb_plant.c) on USART2, which gives the
 * board its clock, serial number, speed limits and lockstep.  No e-stop
 * input: QEMU models no GPIO on this machine. */
#include "clock.h"
#include "sb_motor.h"
#include "serve.h"

#ifdef SB_PLANT_LINK
#include "plant_io.h"
#include "sb_plant.h"
#else
#include "plant.h"
#endif

#define SERIAL 1
#define HOST_BAUD 1000000u /* the reference line: docs/protocol.md, section 5 */

int main(void)
{
    static sb_motor_board board;
    static sb_server server;
    static sb_uart host_line;
    clock_init();
    sb_uart *host = uart_open(&host_line, 1, HOST_BAUD);
    serve_init(&server, host);
    sb_motor_config cfg = {SERIAL, serve_boot_id(), {0}, true, false};
#ifdef SB_PLANT_LINK
    static sb_plant world;
    static sb_plant_io io;
    static sb_uart plant_line;
    io = plant_io_open(&plant_line);
    plant_start(&world, &io, SB_BOARD_MOTOR);
    sb_hal hal = sb_plant_hal(&world);
    cfg.serial = world.info.serial;
    cfg.lockstep = world.info.lockstep;
    for (unsigned ch = 0; ch < SB_MOTORS; ch++) cfg.limit_mtps[ch] = world.info.limit_mtps[ch];
#else
    static plant world;
    plant_init(&world);
    sb_hal hal = plant_hal(&world);
    plant_limits(cfg.limit_mtps);
#endif
    sb_motor_init(&board, &hal, &cfg);
#ifdef SB_PLANT_LINK
    uint32_t last_ms = clock_ms();
#endif
    for (;;) {
#ifdef SB_PLANT_LINK
        plant_refresh(&world, &board.base, host, &last_ms);
#else
        plant_advance(&world, clock_ms());
#endif
        sb_board_poll(&board.base);
        serve_bytes(&server, &board.base);
        uart_sleep(host);
    }
}
