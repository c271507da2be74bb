"""Ascent 3 on a long tread: whether the front pair's reading of the next
riser can be trusted beyond the front cone's rule, and how the robot drives
onto such a tread.

The front cone looks up (the reference robot's: 15 deg wide, tilted 7.5 deg
up).  Across a long tread its top rays pass over a riser as high as the one
being climbed, and a time-of-flight sensor then mixes what lies beyond into
its reading: ``min_rise_for`` refuses a rise too low for the tread it
measured.  Beyond FAR_TREAD_M that rule refused every landing 0.45 to 1.0 m
deep on 0.17 m risers (docs/algorithm.md, "Quarter-turn landings"), yet a
wall, a riser the whole cone sees, or a riser with nothing in range behind it
read right.  What tells them apart is the lift itself: segment 1 rises
number_of_vertical_turns (38 mm on the reference robot) while the pair
measures, and a cone whose top sees over the next riser takes in more of
what lies beyond as it rises, so its reading grows; a wall's stays.  So on a
tread longer than FAR_TREAD_M a rise below ``min_rise_for`` is climbed when
the pair's readings held (:func:`steady`), and refused when they grew.

The readings of the drives onto the step are not used on such a tread
(:func:`near_length`): segment 1 lifted pitches the robot, and the cone's
lower rays then meet the tread itself short of a far riser (the reference
robot on a 0.95 m tread: ascent 6 ended 25 mm short and lifting segment 3
pitched it nose up to the tilt stop).  They go by the seed's turn counts, as
onto the top step.
"""

from __future__ import annotations

import statistics

from stairbot.control.algorithm.phase import Tick
from stairbot.control.algorithm.work import SightWork

FAR_TREAD_M = 0.5
"""A length_of_next_step longer than this: ascent 4, 6 and 9 drive by turns,
and ascent 3 judges a rise below min_rise_for by :func:`steady`.  (Nearer,
they drive by turns too where the front pair, pitched as the robot stands,
meets the tread before the riser: :mod:`~stairbot.control.algorithm.sight`.)"""

STEADY_MIN_M = 0.010
STEADY_SIGMAS = 2.0
"""The pair's readings held over ascent 3's lift when neither sensor's
median over the last third of the lift differs from its first third's by
more than STEADY_SIGMAS of its stated sigma there, and never less than
STEADY_MIN_M.  (Found in the simulation, reference robot: walls and risers
read right moved 0-14 mm; a 0.14 m riser 0.6 m away, read 41 mm long,
grew 34 mm.)"""
MIN_ROWS = 9
"""Fewer readings past the riser than this over the lift: not judged steady."""


def far(length: float | None) -> bool:
    """A length_of_next_step (or tread) past FAR_TREAD_M."""
    return length is not None and length != float("inf") and length > FAR_TREAD_M


def near_length(t: Tick) -> float | None:
    """length_of_next_step for the drives onto the step to end at a reading,
    or None (by turns): not measured, or past FAR_TREAD_M."""
    length = t.ctx.length_of_next_step
    return None if length is None or far(length) else length


def growth(w: SightWork) -> float | None:
    """How much the pair's readings moved over the lift: the larger of SFR's
    and SFL's last-third median less its first-third median, in magnitude;
    None with fewer than MIN_ROWS readings of either."""
    out = 0.0
    for rows in w.rise_rows:
        if len(rows) < MIN_ROWS:
            return None
        third = len(rows) // 3
        change = statistics.median(rows[-third:]) - statistics.median(rows[:third])
        out = max(out, abs(change))
    return out


def steady_m(t: Tick, distance_m: float) -> float:
    """How much the readings may move over the lift and still count as held."""
    return max(STEADY_MIN_M, STEADY_SIGMAS * t.cfg.sensors.sigma(False, distance_m))


def steady(t: Tick, w: SightWork, distance_m: float) -> tuple[bool, float | None]:
    """Whether the pair's readings of a riser ``distance_m`` away held over
    the lift, and by how much they moved (None: too few readings)."""
    grew = growth(w)
    return grew is not None and grew <= steady_m(t, distance_m), grew
