"""Ascent 3 on a long tread (stairbot.control.algorithm.long_tread): whether the
front pair's readings held as segment 1 rose, and the drives onto such a
tread going by turns."""

from __future__ import annotations

import pytest

from stairbot.control.algorithm import long_tread
from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.phase import Tick
from stairbot.control.algorithm.phases import Mode
from stairbot.control.algorithm.work import SightWork
from stairbot.control.robot_config import load_config

CFG = load_config("reference")


def tick(length: float | None = None) -> Tick:
    ctx = Context(length_of_next_step=length)
    return Tick(None, CFG, ctx, Mode.FULL, lambda *a, **k: None)  # type: ignore[arg-type]


def work(right: list[float], left: list[float]) -> SightWork:
    w = SightWork()
    w.rise_rows = [right, left]
    return w


def test_readings_that_hold_as_segment_1_rises_are_steady() -> None:
    flat = [0.900, 0.905, 0.895, 0.902, 0.898, 0.901, 0.899, 0.904, 0.896, 0.900, 0.903, 0.897]
    held, moved = long_tread.steady(tick(), work(flat, flat), 0.9)
    assert held and moved is not None and moved < 0.003


def test_readings_that_grow_as_segment_1_rises_are_not() -> None:
    """A cone whose top sees over the next riser takes in more of what lies
    beyond as it rises: its reading grows (a 0.14 m riser 0.6 m away grew
    34 mm over the lift, read 41 mm long)."""
    flat = [0.61] * 12
    grows = [0.61 + 0.003 * i for i in range(12)]
    held, moved = long_tread.steady(tick(), work(flat, grows), 0.61)
    assert not held and moved == pytest.approx(0.024, abs=0.001)


def test_the_limit_follows_the_sensors_noise_and_is_never_below_10_mm() -> None:
    assert long_tread.steady_m(tick(), 0.3) == pytest.approx(long_tread.STEADY_MIN_M)
    far = long_tread.steady_m(tick(), 0.95)
    assert far == pytest.approx(long_tread.STEADY_SIGMAS * CFG.sensors.sigma(False, 0.95))
    assert far > long_tread.STEADY_MIN_M


def test_too_few_readings_are_not_steady() -> None:
    held, moved = long_tread.steady(tick(), work([0.9] * 20, [0.9] * 3), 0.9)
    assert not held and moved is None


@pytest.mark.parametrize(("length", "reads"), [(None, None), (0.30, 0.30), (0.50, 0.50),
                                               (0.51, None), (0.95, None)])
def test_the_drives_onto_a_tread_past_far_tread_m_go_by_turns(length: float | None,
                                                              reads: float | None) -> None:
    assert long_tread.near_length(tick(length)) == reads
