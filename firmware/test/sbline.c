#include "sbline.h"

#include <stdbool.h>
#include <stdio.h>

static int hexval(char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

void sb_line_feed(const char *hex, sb_reader *reader, sb_board *board)
{
    static uint8_t reply[SB_MAX_WIRE];
    bool any = false;
    for (const char *s = hex; s[0] && s[1]; s += 2) {
        int hi = hexval(s[0]), lo = hexval(s[1]);
        if (hi < 0 || lo < 0) break;
        sb_frame frame;
        if (!sb_reader_push(reader, (uint8_t)(hi << 4 | lo), &frame)) continue;
        size_t n = sb_board_frame(board, &frame, reply);
        for (size_t i = 0; i < n; i++) printf("%02x", reply[i]);
        any = any || n > 0;
    }
    puts(any ? "" : "-");
}
