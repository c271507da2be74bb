/* CRC-16/CCITT-FALSE (docs/protocol.md, section 5): width 16, poly 0x1021,
 * init 0xFFFF, no reflection, xorout 0x0000; check("123456789") = 0x29B1. */
#ifndef SB_CRC_H
#define SB_CRC_H

#include <stddef.h>
#include <stdint.h>

#define SB_CRC_INIT 0xFFFFu

uint16_t sb_crc16(const uint8_t *data, size_t n);

#endif
