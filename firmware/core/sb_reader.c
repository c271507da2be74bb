#include "sb_reader.h"

#include <string.h>

void sb_reader_init(sb_reader *r)
{
    memset(r, 0, sizeof *r);
}

bool sb_reader_push(sb_reader *r, uint8_t byte, sb_frame *out)
{
    if (byte != 0) {
        if (r->skipping) {
            return false;
        }
        if (r->n == SB_MAX_STUFFED) {
            r->stats.overruns++;
            r->skipping = true;
            r->n = 0;
            return false;
        }
        r->buf[r->n++] = byte;
        return false;
    }
    uint16_t n = r->n;
    r->n = 0;
    if (r->skipping) { /* the tail of an overrun: resynchronise here */
        r->skipping = false;
        return false;
    }
    if (n == 0) { /* back-to-back delimiters: a sender flushing the line */
        return false;
    }
    sb_err err = sb_wire_decode(r->buf, n, r->body, out);
    if (err == SB_OK) {
        r->stats.frames++;
        return true;
    }
    if (err == SB_ERR_CRC) {
        r->stats.crc_errors++;
    } else {
        r->stats.malformed++;
    }
    r->last_error = err;
    return false;
}
