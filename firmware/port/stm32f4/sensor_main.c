/* sb_sensor_qemu_link: the sensor board (board/sb_sensor.c) on the
 * STM32F405, serving the host's serial protocol on USART1 (QEMU's first
 * -serial), its range sensors and IMU the simulated robot's over the plant
 * link (plant/sb_plant.c) on USART2, which also gives the board its clock,
 * serial number, channels and lockstep. */
#include "clock.h"
#include "plant_io.h"
#include "sb_plant.h"
#include "sb_sensor.h"
#include "serve.h"

#define HOST_BAUD 1000000u /* the reference line: docs/protocol.md, section 5 */

int main(void)
{
    static sb_sensor_board board;
    static sb_server server;
    static sb_uart host_line, plant_line;
    static sb_plant world;
    static sb_plant_io io;
    clock_init();
    sb_uart *host = uart_open(&host_line, 1, HOST_BAUD);
    serve_init(&server, host);
    io = plant_io_open(&plant_line);
    plant_start(&world, &io, SB_BOARD_SENSOR);
    sb_hal hal = sb_plant_hal(&world);
    sb_sensor_config cfg = {world.info.serial, serve_boot_id(), world.info.channels, true,
                            world.info.lockstep};
    sb_sensor_init(&board, &hal, &cfg);
    uint32_t last_ms = clock_ms();
    for (;;) {
        plant_refresh(&world, &board.base, host, &last_ms);
        sb_board_poll(&board.base);
        serve_bytes(&server, &board.base);
        uart_sleep(host);
    }
}
