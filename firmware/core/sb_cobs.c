#include "sb_cobs.h"

sb_err sb_cobs_encode(const uint8_t *in, size_t n, uint8_t *out, size_t cap, size_t *out_n)
{
    size_t code_at = 0; /* where the current block's code byte goes */
    size_t o = 1;
    uint8_t code = 1;
    if (cap < 1) {
        return SB_ERR_BUFFER;
    }
    for (size_t i = 0; i < n; i++) {
        if (in[i] != 0) {
            if (o >= cap) {
                return SB_ERR_BUFFER;
            }
            out[o++] = in[i];
            code++;
        }
        /* A 0x00 ends a block; so does a full one (code 0xFF: no 0x00 follows)
         * when more input is left, as the host's `cobs` package does. */
        if (in[i] == 0 || (code == 0xFF && i + 1 < n)) {
            if (o >= cap) {
                return SB_ERR_BUFFER;
            }
            out[code_at] = code;
            code_at = o++;
            code = 1;
        }
    }
    out[code_at] = code;
    *out_n = o;
    return SB_OK;
}

sb_err sb_cobs_decode(const uint8_t *in, size_t n, uint8_t *out, size_t cap, size_t *out_n)
{
    size_t i = 0;
    size_t o = 0;
    while (i < n) {
        uint8_t code = in[i++];
        if (code == 0) {
            return SB_ERR_COBS;
        }
        size_t end = i + code - 1u;
        if (end > n) {
            return SB_ERR_COBS;
        }
        for (; i < end; i++) {
            if (in[i] == 0) {
                return SB_ERR_COBS;
            }
            if (o >= cap) {
                return SB_ERR_BUFFER;
            }
            out[o++] = in[i];
        }
        if (i < n && code < 0xFF) {
            if (o >= cap) {
                return SB_ERR_BUFFER;
            }
            out[o++] = 0;
        }
    }
    *out_n = o;
    return SB_OK;
}
