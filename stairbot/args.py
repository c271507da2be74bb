"""argparse types the command lines share: ``stairbot``'s, the fake boards'
and the console's."""

from __future__ import annotations

import argparse
from collections.abc import Callable


def bounded(lo: float, hi: float, unit: str = "") -> Callable[[str], float]:
    """An argparse type: a number from ``lo`` to ``hi`` (finite; nan and inf
    are refused), the message naming the value and the bounds."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
        if not lo <= value <= hi:  # nan fails too
            raise argparse.ArgumentTypeError(
                f"{text!r} is out of range; allowed: {lo:g} to {hi:g}{unit}")
        return value
    parse.__name__ = "number"  # what argparse says when the type fails
    return parse
