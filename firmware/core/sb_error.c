#include "sb_error.h"

static const char *const NAMES[SB_ERR_COUNT] = {
    [SB_OK] = "ok",
    [SB_ERR_SHORT] = "short",
    [SB_ERR_CRC] = "crc",
    [SB_ERR_OLD_FRAMING] = "old_framing",
    [SB_ERR_RESERVED_ADDR] = "reserved_addr",
    [SB_ERR_LENGTH] = "length",
    [SB_ERR_MSG_HEADER] = "msg_header",
    [SB_ERR_MSG_LENGTH] = "msg_length",
    [SB_ERR_PAYLOAD_SIZE] = "payload_size",
    [SB_ERR_PADDING] = "padding",
    [SB_ERR_NO_MESSAGE] = "no_message",
    [SB_ERR_COBS] = "cobs",
    [SB_ERR_TOO_LONG] = "too_long",
    [SB_ERR_FULL] = "full",
    [SB_ERR_RANGE] = "range",
    [SB_ERR_UNKNOWN_TYPE] = "unknown_type",
    [SB_ERR_BUFFER] = "buffer",
};

const char *sb_err_name(sb_err err)
{
    if ((unsigned)err >= SB_ERR_COUNT) {
        return "?";
    }
    return NAMES[err];
}
