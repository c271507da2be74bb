/* Splits a byte stream into frames, one byte at a time (a UART's receive
 * interrupt or loop): bad frames are counted and dropped, and the reader
 * resynchronises at the next 0x00 (docs/protocol.md, section 5).  The same
 * counts as the host's FrameReader (serial_wire.py). */
#ifndef SB_READER_H
#define SB_READER_H

#include <stdbool.h>
#include <stdint.h>

#include "sb_frame.h"

typedef struct {
    uint32_t frames;
    uint32_t crc_errors;
    uint32_t malformed; /* stuffing, length, message errors */
    uint32_t overruns;  /* runs of more than 254 bytes without a delimiter */
} sb_reader_stats;

typedef struct {
    uint8_t buf[SB_MAX_STUFFED];
    uint16_t n;
    bool skipping; /* inside an overrun: drop up to the next 0x00 */
    uint8_t body[SB_MAX_BODY];
    sb_reader_stats stats;
    sb_err last_error;
} sb_reader;

void sb_reader_init(sb_reader *r);

/* Takes one byte.  True when it completed a valid frame, then in *out (its
 * messages point into the reader: valid until the next byte). */
bool sb_reader_push(sb_reader *r, uint8_t byte, sb_frame *out);

#endif
