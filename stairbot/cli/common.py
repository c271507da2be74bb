"""What every ``stairbot`` subcommand shares: its name, the exit codes
(0 as expected, 1 not as expected or a fault, 2 bad input, 130 interrupted)
and :func:`ask`, the operator's confirmation on the terminal."""

from __future__ import annotations

import sys

PROG = "stairbot"
EXIT_OK, EXIT_MISMATCH, EXIT_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130


def ask(prompt: str) -> bool:
    """The operator's answer on the terminal (no terminal: no)."""
    if not sys.stdin.isatty():
        return False
    try:
        return input(prompt).strip().lower() in ("y", "yes")
    except EOFError:
        return False
