/* What the boards' line-protocol test programs (sbboard, sbsensor) share:
 * a "w HEX" command's bytes fed one by one to a board, its reply frames
 * printed. */
#ifndef SB_LINE_H
#define SB_LINE_H

#include "sb_board.h"
#include "sb_reader.h"

/* Feeds the stuffed bytes written in hex (with their delimiters) to board
 * through reader, and prints one line: the reply frames' bytes in hex
 * (stuffed, delimited), or "-" for none.  Stops at the first character that
 * is not a hex digit. */
void sb_line_feed(const char *hex, sb_reader *reader, sb_board *board);

#endif
