"""Figures that follow from the robot config alone, worked out once.

A run asks about one config, every tick; a config is frozen, so what follows
from it never changes.  :func:`per_config` remembers a function's answer for
the config it was last asked about (by identity: hashing a whole config costs
more than the figures it saves).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import TypeVar

from stairbot.inputs.config import RobotConfig

T = TypeVar("T")


def per_config(fn: Callable[[RobotConfig], T]) -> Callable[[RobotConfig], T]:
    """``fn``, remembered for the config it was last asked about."""
    last: tuple[RobotConfig, T] | None = None

    @functools.wraps(fn)
    def remembered(cfg: RobotConfig) -> T:
        nonlocal last
        known = last
        if known is None or known[0] is not cfg:
            known = last = (cfg, fn(cfg))  # one tuple: a reader never sees half of it
        return known[1]

    return remembered
