/* Fuzz the firmware's decoder: N seeded random and mutated frames through
 * sb_frame_parse, sb_wire_decode and one endless sb_reader stream, built with
 * -fsanitize=address,undefined -fno-sanitize-recover=all so that any memory
 * or undefined-behaviour error stops the run with a report.
 *
 *   fuzz_decoder [FRAMES [SEED]]        (defaults 1000000, 1)
 *
 * Inputs: valid frames (random header, 1-6 messages of random types and
 * bytes, some of types the codec does not know) passed through one mutation:
 * none, bit flips, truncation, insertion, deletion (each with the CRC left
 * or made good again), a lying length byte, a lying message length, a
 * changed type code, 01 01 before the delimiter, a long frame near the
 * length limits, random bodies, random line bytes.  Besides the sanitizers it
 * checks, as findings: every unmutated frame is accepted, and every accepted
 * frame re-encodes to the same bytes.  Counts as undetected_corruptions
 * the frames mutated without making the CRC good again that were accepted as
 * another frame (a CRC-16 passes about 1 in 65536).  Prints counts, one "key value" a line. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sb_check.h"
#include "sb_cobs.h"
#include "sb_codec.h"
#include "sb_crc.h"
#include "sb_frame.h"
#include "sb_reader.h"

#define BODY_CAP 320
#define WIRE_CAP 340

enum { M_NONE, M_FLIP, M_FLIP_CRC, M_TRUNC, M_INSERT, M_DELETE, M_LEN_LIE, M_MSG_LEN_LIE,
       M_TYPE, M_ONE_ONE, M_LONG, M_RANDOM_BODY, M_RANDOM_WIRE, M_WIRE_FLIP, M_COUNT };

static const char *const MUTATION[M_COUNT] = {
    "none", "flip", "flip_crc_fixed", "truncate", "insert", "delete", "length_lie",
    "msg_length_lie", "type_change", "one_one_before_delimiter", "long", "random_body",
    "random_wire", "wire_flip"};

static uint64_t rng_state;

static uint32_t rnd(void) /* xorshift64* */
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (uint32_t)((rng_state * 0x2545F4914F6CDD1DULL) >> 32);
}

static uint32_t below(uint32_t n) { return n ? rnd() % n : 0; }

static uint8_t known[256];
static int n_known;
static unsigned long findings;

static void finding(const char *what, unsigned long i)
{
    findings++;
    if (findings <= 10) fprintf(stderr, "finding at frame %lu: %s\n", i, what);
}

/* A random message: a known type with random bytes (reserved bytes zero), or an unknown type. */
static void random_msg(sb_msg *msg)
{
    uint8_t payload[SB_MAX_PAYLOAD];
    uint8_t type;
    int size;
    do {
        type = below(10) == 0 ? (uint8_t)rnd() : known[below((uint32_t)n_known)];
        size = sb_type_known(type) ? sb_payload_size(type) : (int)below(SB_MAX_PAYLOAD + 1);
        for (int i = 0; i < size; i++) payload[i] = (uint8_t)rnd();
        if (type == SB_TRUTH) payload[1] = 0;
    } while (sb_msg_decode(type, payload, (size_t)size, msg) != SB_OK);
}

static size_t valid_body(uint8_t *body, int max_msgs)
{
    sb_writer w;
    sb_msg msg;
    size_t n = 0;
    sb_writer_begin(&w, body, BODY_CAP, (uint8_t)below(16), below(2), (uint8_t)rnd(), (uint8_t)rnd());
    int count = 1 + (int)below((uint32_t)max_msgs);
    for (int i = 0; i < count; i++) {
        random_msg(&msg);
        if (sb_writer_add(&w, &msg) != SB_OK) break;
    }
    sb_writer_finish(&w, &n);
    return n;
}

static void fix_crc(uint8_t *body, size_t n)
{
    if (n < 2) return;
    uint16_t crc = sb_crc16(body, n - 2);
    body[n - 2] = (uint8_t)(crc >> 8);
    body[n - 1] = (uint8_t)crc;
}

static size_t insert(uint8_t *b, size_t n, size_t at, size_t k)
{
    if (n + k > BODY_CAP) return n;
    memmove(b + at + k, b + at, n - at);
    for (size_t i = 0; i < k; i++) b[at + i] = (uint8_t)rnd();
    return n + k;
}

/* Mutates a valid body in place; its new length, and in *crc_fixed whether
 * the CRC was made good again.  The mutations of the stuffed bytes
 * (random_wire, wire_flip, one_one) are the caller's. */
static size_t mutate(int m, uint8_t *b, size_t n, bool *crc_fixed)
{
    bool fix = below(2);
    *crc_fixed = fix || m == M_FLIP_CRC || m == M_LEN_LIE || m == M_MSG_LEN_LIE || m == M_TYPE;
    switch (m) {
    case M_FLIP: case M_FLIP_CRC:
        for (uint32_t k = 1 + below(4); k; k--) b[below((uint32_t)n)] ^= (uint8_t)(1u << below(8));
        if (m == M_FLIP_CRC) fix_crc(b, n);
        return n;
    case M_TRUNC:
        n = below((uint32_t)n);
        if (fix) fix_crc(b, n);
        return n;
    case M_INSERT:
        n = insert(b, n, below((uint32_t)n + 1), 1 + below(4));
        if (fix) fix_crc(b, n);
        return n;
    case M_DELETE: {
        size_t at = below((uint32_t)n), k = 1 + below(4);
        if (at + k > n) k = n - at;
        memmove(b + at, b + at + k, n - at - k);
        n -= k;
        if (fix) fix_crc(b, n);
        return n;
    }
    case M_LEN_LIE:
        b[3] = (uint8_t)(below(2) ? rnd() : b[3] + (below(2) ? 1u : 255u));
        fix_crc(b, n);
        return n;
    case M_MSG_LEN_LIE: case M_TYPE: {
        size_t i = SB_HEADER, target = below(b[3] / 2u + 1u);
        for (; target && i + 2 + b[i + 1] < n - 2; target--) i += 2u + b[i + 1];
        if (m == M_MSG_LEN_LIE) b[i + 1] = (uint8_t)below(16);
        else b[i] = (uint8_t)rnd();
        fix_crc(b, n);
        return n;
    }
    default:
        return n;
    }
}

/* A copy of n bytes in a block of exactly that size, so that AddressSanitizer
 * sees a read one byte past the input (a stack or static buffer would hide it). */
static uint8_t *exact_copy(const uint8_t *p, size_t n)
{
    uint8_t *copy = malloc(n ? n : 1);
    if (copy == NULL) {
        fprintf(stderr, "out of memory\n");
        exit(2);
    }
    memcpy(copy, p, n);
    return copy;
}

/* Every accepted frame: its messages re-encode to the same body, and the board checks run. */
static void check_accepted(const uint8_t *body, size_t n, const sb_frame *f, unsigned long i)
{
    uint8_t again[BODY_CAP];
    size_t again_n = 0;
    sb_writer w;
    sb_msg msg;
    sb_msg_iter it;
    unsigned count = 0;
    sb_writer_begin(&w, again, sizeof again, f->board, f->from_board, f->session, f->seq);
    sb_msg_iter_init(&it, f);
    bool fits = f->msgs_len <= SB_MAX_MSG_BYTES;
    while (sb_msg_iter_next(&it, &msg)) {
        count++;
        (void)sb_check_request(&SB_MOTOR_BOARD, &msg);
        (void)sb_check_request(&SB_SENSOR_BOARD_SIDE, &msg);
        if (fits && sb_writer_add(&w, &msg) != SB_OK) finding("an accepted message does not re-encode", i);
    }
    if (count != f->count) finding("the iterator's count differs from the parser's", i);
    if (fits) {
        if (sb_writer_finish(&w, &again_n) != SB_OK || again_n != n || memcmp(again, body, n) != 0)
            finding("an accepted frame re-encodes to other bytes", i);
    }
}

/* A frame's body for mutation m: valid, long, or random bytes. */
static size_t make_body(int m, uint8_t *body)
{
    size_t n;
    if (m == M_RANDOM_BODY) {
        n = below(300);
        for (size_t k = 0; k < n; k++) body[k] = (uint8_t)rnd();
        if (below(2)) fix_crc(body, n);
        return n;
    }
    if (m == M_LONG) { /* near 247 message bytes (what stuffs in 254) and 255 (the length byte's most) */
        n = valid_body(body, 40);
        while (n < SB_MAX_BODY - 10 + below(20)) n = insert(body, n, n - 2, 1);
        if (below(2)) body[3] = (uint8_t)(n - SB_MIN_BODY);
        fix_crc(body, n);
        return n;
    }
    return valid_body(body, 6);
}

/* What goes on the line for mutation m: the body stuffed (its stuffed bytes
 * flipped, or 01 01 added) or random bytes; its length, 0 when it did not stuff. */
static size_t make_wire(int m, const uint8_t *body, size_t n, uint8_t *wire)
{
    size_t wn = 0;
    if (m == M_RANDOM_WIRE) {
        wn = below(300);
        for (size_t k = 0; k < wn; k++) wire[k] = (uint8_t)(below(8) ? rnd() | 1u : rnd());
        return wn;
    }
    if (sb_cobs_encode(body, n, wire, WIRE_CAP - 2, &wn) != SB_OK) return 0;
    if (m == M_WIRE_FLIP) {
        for (uint32_t k = 1 + below(3); k; k--) wire[below((uint32_t)wn)] ^= (uint8_t)(1u << below(8));
    } else if (m == M_ONE_ONE) {
        wire[wn++] = 1;
        wire[wn++] = 1;
    }
    return wn;
}

typedef struct {
    unsigned long accepted, rejected, body_accepted;
    unsigned long by_err[SB_ERR_COUNT], by_mutation[M_COUNT], undetected_by[M_COUNT];
} counts;

static void report(unsigned long frames, const counts *c, const sb_reader *reader)
{
    unsigned long undetected = 0;
    for (int k = 0; k < M_COUNT; k++) undetected += c->undetected_by[k];
    printf("frames %lu\naccepted %lu\nrejected %lu\nfindings %lu\n", frames, c->accepted,
           c->rejected, findings);
    printf("body_accepted %lu\nundetected_corruptions %lu\n", c->body_accepted, undetected);
    for (int e = 1; e < SB_ERR_COUNT; e++) {
        if (c->by_err[e]) printf("rejected_%s %lu\n", sb_err_name((sb_err)e), c->by_err[e]);
    }
    for (int k = 0; k < M_COUNT; k++) printf("mutation_%s %lu\n", MUTATION[k], c->by_mutation[k]);
    for (int k = 0; k < M_COUNT; k++) {
        if (c->undetected_by[k]) printf("undetected_%s %lu\n", MUTATION[k], c->undetected_by[k]);
    }
    printf("reader_frames %u\nreader_crc_errors %u\nreader_malformed %u\nreader_overruns %u\n",
           (unsigned)reader->stats.frames, (unsigned)reader->stats.crc_errors,
           (unsigned)reader->stats.malformed, (unsigned)reader->stats.overruns);
}

int main(int argc, char **argv)
{
    unsigned long frames = argc > 1 ? strtoul(argv[1], NULL, 10) : 1000000UL;
    unsigned long seed = argc > 2 ? strtoul(argv[2], NULL, 10) : 1UL;
    static counts c;
    static sb_reader reader;
    uint8_t body[BODY_CAP], orig[BODY_CAP], wire[WIRE_CAP];
    uint8_t *unstuffed = calloc(SB_MAX_BODY, 1); /* exactly what sb_wire_decode may fill */
    sb_frame f;
    if (unstuffed == NULL) return 2;
    rng_state = seed * 0x9E3779B97F4A7C15ULL + 1;
    for (int t = 0; t < 256; t++) {
        if (sb_type_known((uint8_t)t)) known[n_known++] = (uint8_t)t;
    }
    sb_reader_init(&reader);
    for (unsigned long i = 0; i < frames; i++) {
        int m = (int)below(M_COUNT);
        bool crc_fixed = false;
        c.by_mutation[m]++;
        size_t orig_n = make_body(m, body);
        memcpy(orig, body, orig_n);
        size_t n = mutate(m, body, orig_n, &crc_fixed);

        /* the body itself, as a board whose transport hands it bodies would parse it */
        uint8_t *input = exact_copy(body, n);
        if (sb_frame_parse(input, n, &f) == SB_OK) {
            c.body_accepted++;
            check_accepted(input, n, &f, i);
        } else if (m == M_NONE) {
            finding("a valid frame was refused", i);
        }
        free(input);

        /* the line's bytes, decoded alone and fed to one endless stream */
        size_t wn = make_wire(m, body, n, wire);
        if (wn == 0 && m != M_RANDOM_WIRE) {
            finding("a body did not stuff", i);
            continue;
        }
        input = exact_copy(wire, wn);
        sb_err err = sb_wire_decode(input, wn, unstuffed, &f);
        free(input);
        if (err == SB_OK) {
            c.accepted++;
            /* a corruption the CRC let through (a CRC-16 passes about 1 in 65536) */
            bool same = f.msgs_len + (size_t)SB_MIN_BODY == orig_n
                        && memcmp(unstuffed, orig, orig_n) == 0;
            if (!crc_fixed && !same && m != M_NONE && m != M_LONG && m != M_RANDOM_BODY
                && m != M_RANDOM_WIRE)
                c.undetected_by[m]++;
        } else {
            c.rejected++;
            c.by_err[err]++;
        }
        for (size_t k = 0; k < wn; k++) (void)sb_reader_push(&reader, wire[k], &f);
        (void)sb_reader_push(&reader, 0, &f);
    }
    free(unstuffed);
    report(frames, &c, &reader);
    return findings ? 1 : 0;
}
