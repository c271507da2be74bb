#include "sb_frame.h"

#include "sb_cobs.h"
#include "sb_codec.h"
#include "sb_crc.h"

static bool crc_ok(const uint8_t *body, size_t n)
{
    uint16_t sent = (uint16_t)((body[n - 2] << 8) | body[n - 1]);
    return sb_crc16(body, n - 2) == sent;
}

sb_err sb_frame_parse(const uint8_t *body, size_t n, sb_frame *out)
{
    if (n < SB_MIN_BODY) {
        /* a 2.x frame without a length byte can be this short: name it */
        if (n >= 4 && !(body[0] & SB_ADDR_FRAMING_3) && crc_ok(body, n)) {
            return SB_ERR_OLD_FRAMING;
        }
        return SB_ERR_SHORT;
    }
    if (!crc_ok(body, n)) {
        return SB_ERR_CRC;
    }
    uint8_t addr = body[0];
    if (!(addr & SB_ADDR_FRAMING_3)) {
        return SB_ERR_OLD_FRAMING;
    }
    if (addr & SB_ADDR_RESERVED) {
        return SB_ERR_RESERVED_ADDR;
    }
    if (body[3] != n - SB_MIN_BODY) {
        return SB_ERR_LENGTH;
    }
    size_t end = n - 2;
    size_t count = 0;
    for (size_t i = SB_HEADER; i < end; count++) {
        if (i + 2 > end) {
            return SB_ERR_MSG_HEADER;
        }
        uint8_t len = body[i + 1];
        if (len > SB_MAX_PAYLOAD || i + 2 + len > end) {
            return SB_ERR_MSG_LENGTH;
        }
        sb_msg scratch;
        sb_err err = sb_msg_decode(body[i], body + i + 2, len, &scratch);
        if (err != SB_OK) {
            return err;
        }
        i += 2u + len;
    }
    if (count == 0) {
        return SB_ERR_NO_MESSAGE;
    }
    out->board = addr & SB_ADDR_BOARD;
    out->from_board = (addr & SB_ADDR_FROM_BOARD) != 0;
    out->session = body[1];
    out->seq = body[2];
    out->count = (uint8_t)count; /* at most 127: 255 bytes of 2 or more */
    out->msgs = body + SB_HEADER;
    out->msgs_len = body[3];
    return SB_OK;
}

void sb_msg_iter_init(sb_msg_iter *it, const sb_frame *frame)
{
    it->frame = frame;
    it->pos = 0;
}

bool sb_msg_iter_next(sb_msg_iter *it, sb_msg *out)
{
    const uint8_t *p = it->frame->msgs + it->pos;
    if (it->pos + 2 > it->frame->msgs_len) {
        return false;
    }
    /* the frame was checked whole by sb_frame_parse: this cannot fail */
    (void)sb_msg_decode(p[0], p + 2, p[1], out);
    it->pos += 2u + p[1];
    return true;
}

sb_err sb_wire_decode(const uint8_t *stuffed, size_t n, uint8_t body[SB_MAX_BODY], sb_frame *out)
{
    size_t body_n = 0;
    if (n > SB_MAX_STUFFED) {
        return SB_ERR_TOO_LONG;
    }
    if (sb_cobs_decode(stuffed, n, body, SB_MAX_BODY, &body_n) != SB_OK) {
        return SB_ERR_COBS;
    }
    return sb_frame_parse(body, body_n, out);
}

sb_err sb_writer_begin(sb_writer *w, uint8_t *buf, size_t cap, uint8_t board, bool from_board,
                       uint8_t session, uint8_t seq)
{
    if (board > SB_ADDR_BOARD) {
        return SB_ERR_RANGE;
    }
    if (cap < SB_MIN_BODY) {
        return SB_ERR_BUFFER;
    }
    w->buf = buf;
    w->cap = cap;
    w->count = 0;
    buf[0] = (uint8_t)(board | SB_ADDR_FRAMING_3 | (from_board ? SB_ADDR_FROM_BOARD : 0u));
    buf[1] = session;
    buf[2] = seq;
    buf[3] = 0;
    w->n = SB_HEADER;
    return SB_OK;
}

sb_err sb_writer_add(sb_writer *w, const sb_msg *msg)
{
    uint8_t payload[SB_MAX_PAYLOAD];
    size_t len = 0;
    sb_err err = sb_msg_encode(msg, payload, &len);
    if (err != SB_OK) {
        return err;
    }
    size_t after = w->n + 2 + len;
    if (after - SB_HEADER > SB_MAX_MSG_BYTES || after + 2 > w->cap) {
        return SB_ERR_FULL;
    }
    w->buf[w->n] = msg->type;
    w->buf[w->n + 1] = (uint8_t)len;
    for (size_t i = 0; i < len; i++) {
        w->buf[w->n + 2 + i] = payload[i];
    }
    w->n = after;
    w->count++;
    return SB_OK;
}

sb_err sb_writer_finish(sb_writer *w, size_t *body_len)
{
    if (w->count == 0) {
        return SB_ERR_NO_MESSAGE;
    }
    w->buf[3] = (uint8_t)(w->n - SB_HEADER);
    uint16_t crc = sb_crc16(w->buf, w->n);
    w->buf[w->n] = (uint8_t)(crc >> 8);
    w->buf[w->n + 1] = (uint8_t)crc;
    *body_len = w->n + 2;
    return SB_OK;
}

sb_err sb_wire_encode(const uint8_t *body, size_t n, uint8_t *out, size_t cap, size_t *out_n)
{
    size_t stuffed = 0;
    if (cap < 1) {
        return SB_ERR_BUFFER;
    }
    sb_err err = sb_cobs_encode(body, n, out, cap - 1, &stuffed);
    if (err != SB_OK) {
        return err;
    }
    out[stuffed] = 0;
    *out_n = stuffed + 1;
    return SB_OK;
}
