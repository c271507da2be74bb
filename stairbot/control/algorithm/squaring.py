"""What calibration measures and how far it may turn: its limits, the front
pair measured standing still (settled, then averaged, trimmed), and the
geometry of a flat riser seen askew.  Shared by the calibration phases
(:mod:`~stairbot.control.algorithm.calibration`,
:mod:`~stairbot.control.algorithm.turns`) and descent's turns back to a
heading."""

from __future__ import annotations

import math

from stairbot.control.algorithm import motion
from stairbot.control.algorithm.moves import Still, stood
from stairbot.control.algorithm.phase import Tick
from stairbot.control.algorithm.work import StandingWork
from stairbot.control.tolerances import settle_s
from stairbot.inputs.config import RobotConfig

PROBE_YAW_RAD = math.radians(10.0)
"""Case 3: the probe turn stops after this much yaw if the readings have not
changed by 2 × equal_tolerance before."""
PROBE_TICKS = 5
"""Case 3: the probe turn compares the mean of its last this many ticks'
readings with their mean standing before it."""
STILL_TICKS = 25
"""Calibration's check averages the pair's difference over this many ticks
(0.5 s at the 20 ms tick) before it decides between the cases."""
MAX_TURN_YAW_RAD = math.radians(90.0)
"""A calibration that turns this far without SFR = SFL ends with an error."""
MAX_SQUARE_YAW_RAD = math.radians(30.0)
"""The most the robot may stand askew of the riser at a calibration: two
readings further apart than both beams on one riser turned this far
(2 × front_lateral × tan 30°, 58 mm on the reference robot) cannot both see
the riser -- the nearer one sees a side wall (case 2W)."""
TURN_MARGIN_RAD = math.radians(12.0)
"""The squaring turn may turn this much more than the readings at its start
say it needs (noise, the mounts' offsets) before it ends with an error: it
never turns on to square up to a side wall."""
MAX_AWAY_YAW_RAD = math.radians(45.0)
"""Case 2W turns away from the side wall at most this far."""
TURN_SLOW_FLOOR = 0.1
"""The squaring turn slows near SFR = SFL, down to this fraction of its speed."""
MAX_TURN_FLIPS = 4
"""The squaring turn may reverse this many times after a check standing
still; the next reversal ends it with an error.  One beam off the flight's
side and the other reading long turned the robot back and forth 6 deg
until the phase timed out 60 s later, with no reason given (SFL 30 mm long
from the start, the robot at the flight's side after four steps askew)."""
MAX_SQUARING_TURNS = 4
"""A calibration that has turned this many times to square up (the squaring
turn, then corrections by the odometer) and still does not read SFR = SFL
standing on all wheels ends with an error."""
LANDING_TURN_MARGIN_RAD = math.radians(15.0)
"""A landing's turn may make this much more than 90° by the odometer before
it ends with an error."""
HEADING_TOLERANCE_RAD = math.radians(0.3)
"""Descent 1 turns back to the heading it climbed the step with, and descent
7 to the one the program began with, when the odometer says it is further
off than this (0.3 deg: 1.6 mm sideways over a 0.3 m climb)."""


def readings(t: Tick) -> tuple[float, float]:
    sfr, sfl = motion.pair(t.snap)
    return sfr.distance_m, sfl.distance_m


def heading_off_rad(t: Tick, twist: float) -> float:
    """How far (radians, + = left) the robot is turned from the heading whose
    odometer twist is ``twist``."""
    return motion.turn_yaw_rad(t.cfg, motion.twist(t.snap) - twist)


def settled(t: Tick, w: Still) -> bool:
    """Standing still since ``w.still_since`` (set now if unset) for as long
    as the filter takes to stand for here (:func:`settle_s`)."""
    return stood(t, w, settle_s(t.cfg))


def measured_standing(t: Tick, w: StandingWork, needed: int) -> bool:
    """True once ``needed`` ticks have been measured; until then, add this
    tick's SFL − SFR to ``w``'s sum when both read a distance.  A reading
    that is an error, a dropout or nothing ahead is no figure for the
    difference: one HC-SR04 dropout (1.3 m) among 25 ticks moves their mean
    by centimetres, enough for a square robot to take the riser for a side
    wall and turn away from it."""
    if len(w.diffs) + w.diff_skipped >= needed:
        return True
    r, l_ = motion.pair(t.snap)
    if r.ok and l_.ok and not motion.far(r, t.cfg) and not motion.far(l_, t.cfg):
        w.diffs.append(l_.distance_m - r.distance_m)
        w.standing.append((r.distance_m, l_.distance_m))
    else:
        w.diff_skipped += 1
    return False


TRIM = 0.2
"""The share of the standing ticks' differences left out at each end before
they are averaged."""


def mean_diff(t: Tick, w: StandingWork) -> float:
    """The mean SFL − SFR measured standing, trimmed of its TRIM highest and
    lowest ticks; now's if no tick gave one.  Two outliers among an HC-SR04's
    last three measurements pass its median and stay for up to three ticks;
    in a plain mean they move it by centimetres, enough for a square robot
    to take the riser for a side wall (case 2W) and turn away from it.
    Trimmed, the mean of normal noise keeps about 90 % of its efficiency."""
    if not w.diffs:
        sfr, sfl = readings(t)
        return sfl - sfr
    return trimmed_mean(w.diffs)


def trimmed_mean(values: list[float]) -> float:
    ordered = sorted(values)
    k = int(len(ordered) * TRIM)
    kept = ordered[k:len(ordered) - k]
    return sum(kept) / len(kept)


def askew_rad(cfg: RobotConfig, diff: float) -> float:
    """How far the robot is turned left of square (radians) when both beams
    on one flat riser read SFL − SFR = ``diff``."""
    return math.atan(diff / (2 * max(cfg.sensors.front_lateral, 1e-6)))


def one_riser(cfg: RobotConfig) -> float:
    """The largest SFL − SFR (either sign) both beams on one riser can read,
    the robot turned MAX_SQUARE_YAW_RAD from square to it."""
    return 2 * cfg.sensors.front_lateral * math.tan(MAX_SQUARE_YAW_RAD)
