#include "sb_crc.h"

/* Bit by bit: 8 shifts a byte, no table (a board has cycles to spare at 1 Mbaud
 * and flash to save). */
uint16_t sb_crc16(const uint8_t *data, size_t n)
{
    uint16_t crc = SB_CRC_INIT;
    for (size_t i = 0; i < n; i++) {
        uint32_t c = crc ^ ((uint32_t)data[i] << 8);
        for (int bit = 0; bit < 8; bit++) {
            c = (c & 0x8000u) ? (c << 1) ^ 0x1021u : c << 1;
        }
        crc = (uint16_t)c;
    }
    return crc;
}
