/* The errors of the serial wire's codec: each names one way input is wrong.
 * docs/protocol.md, section 5 ("Receiving") lists the checks in this order. */
#ifndef SB_ERROR_H
#define SB_ERROR_H

typedef enum {
    SB_OK = 0,
    SB_ERR_SHORT,         /* a frame of fewer than 6 bytes (header and CRC) */
    SB_ERR_CRC,           /* the CRC does not match */
    SB_ERR_OLD_FRAMING,   /* address bit 4 clear: protocol 2.x framing, no length byte */
    SB_ERR_RESERVED_ADDR, /* address bits 5-6 set */
    SB_ERR_LENGTH,        /* the length byte contradicts the bytes between header and CRC */
    SB_ERR_MSG_HEADER,    /* a message's type and length bytes cut by the CRC */
    SB_ERR_MSG_LENGTH,    /* a message length above 8, or running past the CRC */
    SB_ERR_PAYLOAD_SIZE,  /* a known type with a payload of another size */
    SB_ERR_PADDING,       /* a reserved payload byte that is not zero */
    SB_ERR_NO_MESSAGE,    /* a frame without a message */
    SB_ERR_COBS,          /* stuffed bytes holding 0x00, or a code running past the end */
    SB_ERR_TOO_LONG,      /* more than 254 stuffed bytes between delimiters */
    SB_ERR_FULL,          /* writer: the message does not fit in the frame */
    SB_ERR_RANGE,         /* encoder: a value out of its field's wire range */
    SB_ERR_UNKNOWN_TYPE,  /* encoder: a type code the codec does not know */
    SB_ERR_BUFFER,        /* an output buffer too small */
    SB_ERR_COUNT
} sb_err;

/* A constant name for an error ("crc", "length", ...); "?" for none. */
const char *sb_err_name(sb_err err);

#endif
