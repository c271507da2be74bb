"""The step being descended, as every descent phase reads it: its
tab_length_to_edge, its tread as ascent 3 measured it, whether it is narrow,
and the height descent 2 measured."""

from __future__ import annotations

from stairbot.control.algorithm.lift_first import narrow
from stairbot.control.algorithm.phase import Tick


def step_tab(t: Tick) -> float | None:
    """tab_length_to_edge of the step being descended."""
    return t.ctx.tab_length_to_edge[t.descent_index]


def step_tread(t: Tick) -> float | None:
    """The tread ascent 3 measured for the step being descended (None: not
    measured, or not climbed)."""
    i = t.descent_index
    return t.ctx.tread_length[i] if 0 <= i < len(t.ctx.tread_length) else None


def height(t: Tick) -> float:
    """number_of_turns_for_step_height."""
    return t.ctx.number_of_turns_for_step_height


def narrow_here(t: Tick, index: int | None = None) -> bool:
    """The tread of step ``index`` (default: the one being descended, which
    the robot stands on) is narrow: the robot does not fit on it, and its
    segment 3 hangs in the air over the step below (narrow_steps)."""
    i = t.descent_index if index is None else index
    return not t.ctx.from_top and 0 <= i and narrow(t.cfg, t.ctx.tread_length[i])
