"""The ``stairbot`` command: the parser and dispatch (``command``; its
``main`` is the console script's entry point, ``stairbot.cli:main``),
``stairbot run`` (``run``), the commands that show inputs (``show``),
``stairbot clear`` (``clear``), and what every subcommand shares
(``common``).  The top of the house: nothing below imports it."""

from stairbot.cli.command import main

__all__ = ["main"]
