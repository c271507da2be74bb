/* Consistent Overhead Byte Stuffing (docs/protocol.md, section 5): a frame
 * holds no 0x00 on the wire; a 0x00 delimits it.  Decoding follows the host's
 * `cobs` package: a code byte n copies n-1 bytes and, unless n is 0xFF or the
 * input ends, a 0x00. */
#ifndef SB_COBS_H
#define SB_COBS_H

#include <stddef.h>
#include <stdint.h>

#include "sb_error.h"

/* Stuffs n bytes into out (at most cap); *out_n the stuffed length (no
 * delimiter).  SB_ERR_BUFFER when out is too small: n + n/254 + 1 bytes do. */
sb_err sb_cobs_encode(const uint8_t *in, size_t n, uint8_t *out, size_t cap, size_t *out_n);

/* Unstuffs n bytes into out (at most cap).  SB_ERR_COBS for a 0x00 in the
 * input or a code running past its end; SB_ERR_BUFFER when out is too small
 * (n bytes always do). */
sb_err sb_cobs_decode(const uint8_t *in, size_t n, uint8_t *out, size_t cap, size_t *out_n);

#endif
