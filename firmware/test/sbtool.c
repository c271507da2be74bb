/* The native test program: reads commands, one a line, on stdin and answers
 * each with one line on stdout, so that tests/firmware/test_c_codec.py can
 * hold the C codec against the Python one.  Hex is given without spaces;
 * "-" is no bytes.
 *
 *   body HEX            parse an unstuffed frame  -> ok FRAME | err NAME
 *   wire HEX            decode stuffed bytes      -> ok FRAME | err NAME
 *   stream HEX          feed a byte stream        -> [FRAME || ]... frames F crc C malformed M overruns O
 *   enc B F S Q | MSG | MSG ...                   -> ok BODYHEX WIREHEX | err NAME
 *   check BOARD HEX     a body's messages checked -> ok RESULT... | err NAME
 *                       (BOARD: motor, sensor, sensor6, motor_sim)
 *   crc HEX             CRC-16 of the bytes       -> 4 hex digits
 *
 * FRAME is "B F S Q | MSG | MSG ...": board, from_board (0/1), session, seq;
 * MSG is "TYPE V1 V2 ..." (decimal type code, then the fields in records.py's
 * order) or "raw TYPE HEX" for a type the codec does not know. */
#define _POSIX_C_SOURCE 200809L /* strtok_r: this program runs on the build machine only */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sb_check.h"
#include "sb_codec.h"
#include "sb_crc.h"
#include "sb_frame.h"
#include "sb_reader.h"

#define LINE_MAX_CHARS 65536

static char line[LINE_MAX_CHARS];
static uint8_t bytes[LINE_MAX_CHARS / 2];

static int hexval(char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* Hex digits to bytes; -1 for anything else. */
static long unhex(const char *s, uint8_t *out)
{
    if (strcmp(s, "-") == 0) return 0;
    long n = 0;
    for (; s[0] && s[1]; s += 2) {
        int hi = hexval(s[0]), lo = hexval(s[1]);
        if (hi < 0 || lo < 0) return -1;
        out[n++] = (uint8_t)(hi << 4 | lo);
    }
    return s[0] ? -1 : n;
}

static void print_hex(const uint8_t *p, size_t n)
{
    if (n == 0) fputs("-", stdout);
    for (size_t i = 0; i < n; i++) printf("%02x", p[i]);
}

static void print_frame(const sb_frame *f)
{
    sb_msg_iter it;
    sb_msg msg;
    printf("%u %u %u %u", f->board, f->from_board ? 1u : 0u, f->session, f->seq);
    sb_msg_iter_init(&it, f);
    while (sb_msg_iter_next(&it, &msg)) {
        if (!msg.known) {
            printf(" | raw %u ", msg.type);
            print_hex(msg.body.raw.payload, msg.body.raw.len);
            continue;
        }
        printf(" | %u", msg.type);
        for (int i = 0; i < sb_msg_field_count(msg.type); i++) {
            printf(" %lld", (long long)sb_msg_field(&msg, i));
        }
    }
}

static void answer_frame(sb_err err, const sb_frame *f)
{
    if (err != SB_OK) {
        printf("err %s", sb_err_name(err));
        return;
    }
    fputs("ok ", stdout);
    print_frame(f);
}

static void cmd_stream(long n)
{
    sb_reader r;
    sb_frame f;
    sb_reader_init(&r);
    for (long i = 0; i < n; i++) {
        if (sb_reader_push(&r, bytes[i], &f)) {
            print_frame(&f); /* now: its messages live in the reader */
            fputs(" || ", stdout);
        }
    }
    printf("frames %u crc %u malformed %u overruns %u", (unsigned)r.stats.frames,
           (unsigned)r.stats.crc_errors, (unsigned)r.stats.malformed, (unsigned)r.stats.overruns);
}

/* "raw TYPE HEX" or "TYPE V..." into a message. */
static sb_err parse_msg(char *text, sb_msg *msg)
{
    char *save = NULL;
    char *tok = strtok_r(text, " ", &save);
    if (tok == NULL) return SB_ERR_NO_MESSAGE;
    if (strcmp(tok, "raw") == 0) {
        char *type = strtok_r(NULL, " ", &save), *hex = strtok_r(NULL, " ", &save);
        uint8_t payload[LINE_MAX_CHARS / 2];
        long n = hex ? unhex(hex, payload) : -1;
        if (type == NULL || n < 0 || n > SB_MAX_PAYLOAD) return SB_ERR_RANGE;
        memset(msg, 0, sizeof *msg);
        msg->type = (uint8_t)strtol(type, NULL, 10);
        msg->body.raw.len = (uint8_t)n;
        memcpy(msg->body.raw.payload, payload, (size_t)n);
        return SB_OK;
    }
    sb_err err = sb_msg_init(msg, (uint8_t)strtol(tok, NULL, 10));
    for (int i = 0; err == SB_OK && (tok = strtok_r(NULL, " ", &save)) != NULL; i++) {
        err = sb_msg_set_field(msg, i, strtoll(tok, NULL, 10));
    }
    return err;
}

static void cmd_enc(char *args)
{
    uint8_t body[SB_MAX_BODY], wire[SB_MAX_WIRE];
    size_t body_n = 0, wire_n = 0;
    unsigned board, from, session, seq;
    sb_writer w;
    sb_msg msg;
    char *save = NULL;
    char *part = strtok_r(args, "|", &save);
    if (part == NULL || sscanf(part, "%u %u %u %u", &board, &from, &session, &seq) != 4) {
        printf("err usage");
        return;
    }
    sb_err err = sb_writer_begin(&w, body, sizeof body, (uint8_t)board, from != 0,
                                 (uint8_t)session, (uint8_t)seq);
    while (err == SB_OK && (part = strtok_r(NULL, "|", &save)) != NULL) {
        err = parse_msg(part, &msg);
        if (err == SB_OK) err = sb_writer_add(&w, &msg);
    }
    if (err == SB_OK) err = sb_writer_finish(&w, &body_n);
    if (err == SB_OK) err = sb_wire_encode(body, body_n, wire, sizeof wire, &wire_n);
    if (err != SB_OK) {
        printf("err %s", sb_err_name(err));
        return;
    }
    fputs("ok ", stdout);
    print_hex(body, body_n);
    fputs(" ", stdout);
    print_hex(wire, wire_n);
}

static void cmd_check(const char *board, long n)
{
    const sb_board_caps motor_sim = {6, 0, 0, true};
    const sb_board_caps *caps = strcmp(board, "motor") == 0 ? &SB_MOTOR_BOARD
                                : strcmp(board, "sensor") == 0 ? &SB_SENSOR_BOARD
                                : strcmp(board, "sensor6") == 0 ? &SB_SENSOR_BOARD_SIDE
                                : strcmp(board, "motor_sim") == 0 ? &motor_sim : NULL;
    sb_frame f;
    sb_msg_iter it;
    sb_msg msg;
    if (caps == NULL) {
        printf("err usage");
        return;
    }
    sb_err err = sb_frame_parse(bytes, (size_t)n, &f);
    if (err != SB_OK) {
        printf("err %s", sb_err_name(err));
        return;
    }
    fputs("ok", stdout);
    sb_msg_iter_init(&it, &f);
    while (sb_msg_iter_next(&it, &msg)) printf(" %d", (int)sb_check_request(caps, &msg));
}

static void run(char *cmd)
{
    char *save = NULL;
    char *verb = strtok_r(cmd, " ", &save);
    if (verb != NULL && strcmp(verb, "enc") == 0) {
        cmd_enc(save);
        return;
    }
    bool check = verb != NULL && strcmp(verb, "check") == 0;
    char *board = check ? strtok_r(NULL, " ", &save) : NULL;
    char *hex = strtok_r(NULL, " ", &save);
    long n = hex ? unhex(hex, bytes) : -1;
    sb_frame f;
    uint8_t body[SB_MAX_BODY];
    if (n < 0 || (check && board == NULL)) {
        printf("err usage");
    } else if (strcmp(verb, "body") == 0) {
        answer_frame(sb_frame_parse(bytes, (size_t)n, &f), &f);
    } else if (strcmp(verb, "wire") == 0) {
        answer_frame(sb_wire_decode(bytes, (size_t)n, body, &f), &f);
    } else if (strcmp(verb, "stream") == 0) {
        cmd_stream(n);
    } else if (check) {
        cmd_check(board, n);
    } else if (strcmp(verb, "crc") == 0) {
        printf("%04x", sb_crc16(bytes, (size_t)n));
    } else {
        printf("err usage");
    }
}

int main(void)
{
    while (fgets(line, sizeof line, stdin) != NULL) {
        line[strcspn(line, "\r\n")] = 0;
        run(line);
        putchar('\n');
        fflush(stdout);
    }
    return 0;
}
