"""A squaring turn that chases a front sensor's offset (not in the seed).

A front sensor that reads a constant offset moves as a healthy one does
when the robot turns on the spot: the turn's geometry does not show it,
and calibration turns until SFR = SFL, askew of the riser by
``askew_rad(offset)`` (17° for 3 cm on a 0.1 m pair), or, an HC-SR04
pair, until both beams meet the riser too obliquely to hear an echo and
"square up" to nothing.

On a climbed step the odometer knows better: descent 1 turned back to the
heading the step was climbed with (:mod:`~stairbot.control.algorithm.calibration`),
which calibration squared to the riser while both sensors read it alike,
and a flight's risers are parallel.  Square to this riser lies within
:func:`allowed_rad` of that heading: what each of the two squarings may
leave (:func:`~stairbot.control.tolerances.square_tolerance` as a yaw) and
what the odometer's heading may have drifted over the step
(:data:`STEP_DRIFT_M` of one wheel's slip over the track).  A squaring turn
in descent 1 that takes the robot further than that from the climbed
heading, or stops with both beams reading nothing ahead where, lowered on
all wheels, neither meets the riser either, is not squaring to it: the
pair disagrees by an offset.  The robot turns back to the climbed heading
by the odometer, lowers, and measures the pair standing still as the
check that began the turn did (``cal.checked``): the same pose gives the
same readings, so a sensor whose reading there changed while its
partner's did not carries an offset that began in the turn, and is
judged biased (:func:`at_check`); if neither changed, nothing names which
carries it, and both front sensors are distrusted (:func:`distrusted`, as
:mod:`~stairbot.control.algorithm.blind` does at the end of the standing
rule's wait).  Either way they read as ERROR, and the limp home sees them
lost.  A sensor that held one value through the turn is left to the stuck
rule (:func:`~stairbot.control.algorithm.turns._held_through`).

Anywhere else (the start's calibration, ascent 1: no heading known to be
square) only a turn that stopped over no reading and, lowered on all
wheels, still meets no riser is taken for a chase: it turns back to the
heading its check measured the pair at and judges as above, and where
neither sensor is named the program stops, saying that one front sensor
may read an offset.  A turn that lost both beams with segments 1 and 3
lifted, whose beams meet the riser again lowered (a cone tilted up sees
over a low riser, a clearance higher), goes on squaring up.
"""

from __future__ import annotations

import math

from stairbot.control.algorithm import blind, limits, motion
from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.families import Calibration
from stairbot.control.algorithm.modes import Purpose
from stairbot.control.algorithm.phase import NO_MOTION, Step, Tick, fail, go, stay, where
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.squaring import (
    STILL_TICKS,
    askew_rad,
    measured_standing,
    settled,
    trimmed_mean,
)
from stairbot.control.algorithm.texts import squaring_bias as say
from stairbot.control.algorithm.work import StandingWork
from stairbot.control.tolerances import square_tolerance, still_tolerance
from stairbot.hardware import FRONT_SENSORS, SensorId
from stairbot.inputs.config import RobotConfig

STEP_DRIFT_M = 0.0135
"""How far the odometer drifts over a step climbed and descended (2.7 cm
from the start after two steps as the simulation measured it:
docs/algorithm.md, descent 7 by the odometer).  Taken whole as one wheel's slip against the
other, it turns the heading the odometer does not see by this over the
track width (4.8° on a 0.16 m track)."""


def allowed_rad(cfg: RobotConfig, distance_m: float) -> float:
    """How far square to the riser ``distance_m`` ahead may lie from the
    heading the step was climbed with: the climb's squaring (at most as
    far as the start's, square_range_m, and nearer than nothing ahead),
    this one's, and the odometer's drift over the step."""
    start = min(limits.square_range_m(cfg), cfg.LENGTH_OF_INFINITY)
    climbed = square_tolerance(cfg, max(distance_m, start))
    here = square_tolerance(cfg, distance_m)
    drift = STEP_DRIFT_M / cfg.geometry.track_width
    return askew_rad(cfg, climbed) + askew_rad(cfg, here) + drift


def _climbed(t: Tick) -> float | None:
    """The heading (odometer twist) descent 1's step was climbed with; None
    elsewhere, or not known (a continuous descent)."""
    ctx = t.ctx
    if t.cal.purpose is not Purpose.DESCENT or ctx.from_top:
        return None
    return ctx.climb_twist[t.descent_index]


def _near(t: Tick) -> float:
    """The nearer of the pair's distances (as far as the start's squaring,
    if neither reads one)."""
    seen = [r.distance_m for r in motion.pair(t.snap)
            if r.ok and not motion.far(r, t.cfg) and math.isfinite(r.distance_m)]
    return min(seen, default=min(limits.square_range_m(t.cfg), t.cfg.LENGTH_OF_INFINITY))


def past(t: Tick, twist: float | None = None) -> bool:
    """Descent 1 on a climbed step: whether the heading ``twist`` (the
    odometer's now, if None) lies further from the one the step was climbed
    with than :func:`allowed_rad` (once a calibration)."""
    climbed = _climbed(t)
    if climbed is None or t.cal.chased is not None:
        return False
    now = motion.twist(t.snap) if twist is None else twist
    return abs(motion.turn_yaw_rad(t.cfg, now - climbed)) > allowed_rad(t.cfg, _near(t))


def beyond(t: Tick, twist: float | None = None, lost: bool = False) -> Step | None:
    """Descent 1 on a climbed step, :func:`past` for ``twist``, or (``lost``)
    both beams read nothing ahead: turn back to the climbed heading, the
    pair to be distrusted once lowered (module docstring).  None: go on as
    before."""
    climbed, cal = _climbed(t), t.cal
    if climbed is None or cal.chased is not None or not (lost or past(t, twist)):
        return None
    now = motion.twist(t.snap) if twist is None else twist
    off = motion.turn_yaw_rad(t.cfg, now - climbed)
    allowed = allowed_rad(t.cfg, _near(t))
    sfr, sfl = motion.pair(t.snap)
    cal.chased = say.chased(t.descent_index, off, allowed, sfr.distance_m, sfl.distance_m, lost)
    cal.turn_to = climbed
    t.ctx.descent.turned_back = True
    t.say(cal.chased, off_deg=math.degrees(off), allowed_deg=math.degrees(allowed))
    return go("chased")


def lost_both(t: Tick, made_rad: float) -> Step:
    """A squaring turn stopped with both beams reading nothing ahead, and
    lowered on all wheels neither meets the riser: on a climbed step,
    :func:`beyond`; elsewhere back to the heading the turn began from, if
    its check measured the pair there, to see which reading changed
    (:func:`at_check`); else the program stops, saying why."""
    step = beyond(t, lost=True)
    if step is not None:
        return step
    cal, (sfr, sfl) = t.cal, motion.pair(t.snap)
    lost = say.lost_both(where(t.ctx, Phase.CAL_CHECK), made_rad, sfr.distance_m,
                         sfl.distance_m)
    if cal.checked is None or cal.chased is not None:
        return fail(lost)
    cal.chased, cal.turn_to = lost, cal.checked[2]
    t.say(say.turning_back(lost))
    return go("chased")


def at_check(t: Tick, w: StandingWork) -> Step | None:
    """Calibration's check on the heading a chase turned back to
    (:func:`beyond`, :func:`lost_both`): measured standing still as the
    check that began the turn was, a sensor whose reading there changed by
    more than the pair's noise while its partner's did not carries an
    offset that began meanwhile, and is judged biased; if neither can be
    named, descent 1 distrusts both and the start or ascent 1 stops.  The
    sensors so judged read as ERROR from the next tick on
    (:func:`distrusted`): lost, the limp home follows.  With both front
    sensors lost, descent 1 goes on to back up to the edge on the climbed
    heading.  None: no chase, or limping on the named sensor's partner."""
    cal, ctx = t.cal, t.ctx
    if cal.chased is None:
        return None
    if cal.verdict is not None:
        if blind.front_unusable(ctx):
            return go("square_to_descend")
        return None if ctx.limp is not None else stay(NO_MOTION)
    if not settled(t, w) or not measured_standing(t, w, STILL_TICKS):
        return stay(NO_MOTION)
    cal.verdict = _judged(t, w)
    if cal.verdict[0] == BOTH and cal.purpose is not Purpose.DESCENT:
        return fail(cal.verdict[1])
    t.say(cal.verdict[1])
    return stay(NO_MOTION)


BOTH = "both"
"""A verdict that names neither sensor."""


def _judged(t: Tick, w: StandingWork) -> tuple[str, str]:
    """The sensor whose trimmed mean standing now differs from the check's
    before the turn by more than twice the tolerance of such a mean
    (:func:`~stairbot.control.tolerances.still_tolerance`), its partner's
    by no more than once: the same pose, by the odometer, gives the same
    readings."""
    cal, chased = t.cal, t.cal.chased
    assert chased is not None
    if cal.checked is None or not w.standing:
        return BOTH, say.unnamed(chased, None)
    now = (trimmed_mean([r for r, _l in w.standing]),
           trimmed_mean([l_ for _r, l_ in w.standing]))
    moved = (now[0] - cal.checked[0], now[1] - cal.checked[1])
    tol = still_tolerance(t.cfg, len(w.standing), min(now))
    for i, sensor in enumerate(FRONT_SENSORS):
        if abs(moved[1 - i]) <= tol < abs(moved[i]) / 2:
            return sensor.value, say.named(sensor.value, moved[i], FRONT_SENSORS[1 - i].value,
                                           moved[1 - i], chased)
    return BOTH, say.unnamed(chased, moved)


def distrusted(ctx: Context, phase: Phase) -> dict[SensorId, str]:
    """The front sensors :func:`at_check` judged, with why, while the robot
    stands in calibration's check (both: in descent 1 only); else none."""
    family = ctx.family
    if phase is not Phase.CAL_CHECK or not isinstance(family, Calibration) \
            or family.verdict is None:
        return {}
    who, why = family.verdict
    if who != BOTH:
        return {SensorId(who): why}
    if family.purpose is not Purpose.DESCENT:
        return {}
    return dict(zip(FRONT_SENSORS, say.distrusted(why), strict=True))
