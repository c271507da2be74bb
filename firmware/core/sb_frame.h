/* The serial wire's frame (docs/protocol.md, section 5): header (addr,
 * session, seq, len), one or more messages (type, len, payload), CRC-16
 * big-endian; COBS-stuffed on the wire and followed by a 0x00.
 *
 * Parsing checks the whole frame before a message is handed out, so a board
 * never executes half of a frame it then finds malformed. */
#ifndef SB_FRAME_H
#define SB_FRAME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "sb_error.h"
#include "sb_msg.h"

#define SB_HEADER 4            /* addr, session, seq, len */
#define SB_MIN_BODY 6          /* the header and the CRC */
#define SB_MAX_STUFFED 254     /* stuffed bytes between two delimiters */
#define SB_MAX_BODY 253        /* the longest body that stuffs into 254 bytes */
#define SB_MAX_MSG_BYTES (SB_MAX_BODY - SB_MIN_BODY) /* 247: what a writer puts in one frame */
#define SB_MAX_WIRE (SB_MAX_STUFFED + 1)             /* with the delimiter */

#define SB_ADDR_BOARD 0x0Fu
#define SB_ADDR_FRAMING_3 0x10u /* always set: the header has a length byte */
#define SB_ADDR_RESERVED 0x60u  /* always clear */
#define SB_ADDR_FROM_BOARD 0x80u

/* A checked frame: its header, and its messages still as bytes in the body
 * it was parsed from (valid while that body is). */
typedef struct {
    uint8_t board;
    bool from_board;
    uint8_t session;
    uint8_t seq;
    uint8_t count; /* messages */
    const uint8_t *msgs;
    uint8_t msgs_len;
} sb_frame;

/* Checks an unstuffed frame (CRC included) as section 5 says, in its order:
 * size, CRC, address bit 4, reserved address bits, the length byte, each
 * message's length and payload (known types: size and reserved bytes), at
 * least one message.  The first failure is returned; SB_OK fills *out. */
sb_err sb_frame_parse(const uint8_t *body, size_t n, sb_frame *out);

/* The messages of a parsed frame, in order. */
typedef struct {
    const sb_frame *frame;
    size_t pos;
} sb_msg_iter;

void sb_msg_iter_init(sb_msg_iter *it, const sb_frame *frame);
/* The next message into *out; false after the last. */
bool sb_msg_iter_next(sb_msg_iter *it, sb_msg *out);

/* Unstuffs the bytes between two delimiters into body (SB_MAX_BODY bytes)
 * and parses them.  SB_ERR_TOO_LONG above SB_MAX_STUFFED bytes, SB_ERR_COBS
 * for bad stuffing, then sb_frame_parse's errors. */
sb_err sb_wire_decode(const uint8_t *stuffed, size_t n, uint8_t body[SB_MAX_BODY], sb_frame *out);

/* Builds a frame's body in a caller's buffer: begin, add each message, finish. */
typedef struct {
    uint8_t *buf;
    size_t cap;
    size_t n;
    uint8_t count;
} sb_writer;

/* SB_ERR_RANGE for a board above 15; SB_ERR_BUFFER below SB_MIN_BODY bytes. */
sb_err sb_writer_begin(sb_writer *w, uint8_t *buf, size_t cap, uint8_t board, bool from_board,
                       uint8_t session, uint8_t seq);
/* SB_ERR_FULL when the message would take the frame past SB_MAX_MSG_BYTES
 * (or past cap): the frame is unchanged, and the replies left off are those
 * from this one on (section 5).  The codec's errors for a bad message. */
sb_err sb_writer_add(sb_writer *w, const sb_msg *msg);
/* Writes the length byte and the CRC; *body_len the frame's size.
 * SB_ERR_NO_MESSAGE for a frame without a message. */
sb_err sb_writer_finish(sb_writer *w, size_t *body_len);

/* A body stuffed and delimited: what goes on the line (at most SB_MAX_WIRE bytes). */
sb_err sb_wire_encode(const uint8_t *body, size_t n, uint8_t *out, size_t cap, size_t *out_n);

#endif
