/* What the boards' Linux programs share: their arguments, the host's line
 * (a new pty, a tty's path, or an inherited descriptor), the plant link on
 * an inherited descriptor, and the loop serving one board on the line. */
#ifndef SB_NATIVE_H
#define SB_NATIVE_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "sb_board.h"
#include "sb_frame.h"
#include "sb_plant.h"

typedef struct {
    const char *name;  /* the program's, for messages */
    long serial;       /* --serial N (0: not given) */
    int host_fd;       /* --host-fd N (-1: not given) */
    int plant_fd;      /* --plant-fd N (-1: not given) */
    const char *path;  /* a tty to open (NULL: none given) */
} sb_native_args;

/* One board as the loop serves it, and its plant: the plant link (asked
 * before each poll, told the board's flags and its e-stop button), or else
 * a plant the loop advances to the wall clock's milliseconds. */
typedef struct {
    sb_board *board;
    sb_plant *plant;
    void (*advance)(uint32_t wall_ms);
} sb_native_board;

/* The e-stop button: SIGUSR1 presses it, SIGUSR2 releases it. */
extern volatile sig_atomic_t sb_native_button;

/* Parses [--serial N] [--host-fd N] [--plant-fd N] [PATH]; 0, or 2 after
 * printing the usage with why. */
int sb_native_args_parse(int argc, char **argv, sb_native_args *a);

/* The host's line: --host-fd, else PATH opened raw, else a new pty whose
 * path is printed on stdout's first line.  -1 after saying why. */
int sb_native_open_host(const sb_native_args *a);

/* The plant link on descriptor fd (a socket): bytes out, bytes in with a timeout. */
sb_plant_io sb_native_plant_io(int *fd);

/* A boot id drawn at start (Owner.boot), never 0. */
uint32_t sb_native_boot_id(void);

/* Serves nb on fd until SIGTERM, SIGINT or the plant is gone; prints the
 * board's and the line's counts on stderr.  Returns the exit code. */
int sb_native_serve(int fd, const sb_native_args *a, const sb_native_board *nb);

#endif
