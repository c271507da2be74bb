"""The standing rule: when the two sensors of a pair disagree, stop every
motor, wait standing_wait seconds on the controller's clock, measure again;
resume exactly where it stopped if they agree, end with an error if not.

Armed in the phases whose record names a pair in ``watches`` (where both
sensors of the pair look at the same flat surface): SBR/SBL in descent 2,
SFR/SFL elsewhere.  A disagreement only counts when both sensors give a
usable distance, and both the (filtered) difference and its smoothed value
(:data:`~stairbot.control.algorithm.motion.DIFF_SMOOTHING`) must exceed their
tolerances for DEBOUNCE_TICKS ticks in a row: what calibration may have left
when it squared up, plus four sigmas of the difference from the sensors'
stated noise (:func:`~stairbot.control.tolerances.standing_tolerance`).  Neither a
short spike, sensor noise, nor a yaw calibration accepted stops the robot.

:func:`watch` runs before an armed phase's step and returns the pause; the
PAUSED phase's step returns the resume (to the phase it stopped in) or the
error.  The controller does the bookkeeping of both.
"""

from __future__ import annotations

import statistics
from typing import Any

from stairbot.control.algorithm import back_apart, blind, long_tread, motion
from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.phase import (
    FAILED,
    FAULT,
    NO_MOTION,
    Exit,
    PhaseDef,
    Step,
    Tick,
    fail,
    go,
    stay,
)
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.texts import limp as say_limp
from stairbot.control.algorithm.texts import shared as say
from stairbot.control.algorithm.work import Work
from stairbot.control.tolerances import standing_tolerance
from stairbot.hardware import SensorStatus, Snapshot
from stairbot.inputs.config import RobotConfig

BY_TURNS_ONTO = frozenset({Phase.ASCENT_DRIVE_FIRST, Phase.ASCENT_LIFT_SECOND,
                           Phase.ASCENT_DRIVE_SECOND})
"""Ascent 4 to 6: onto a step the robot drives by turns (long_tread.near_length
None), the front pair's rule is not armed.  It is in ascent 7, where the pair
reads the tab: unarmed there, one sensor reading short would go unseen, the
tab would be stored short, and descent 1 would stop segment 3 short of the
edge."""
_BY_TURNS_ONTO = tuple(BY_TURNS_ONTO)  # asked every tick: a Phase's hash is Python's
DISAGREE = "disagree"
"""The outcome of :func:`watch`: the pause, which the transition table adds to
every armed phase."""


def resumed(phase: Phase) -> str:
    """The PAUSED phase's outcome that resumes ``phase`` (the table adds one
    for every armed phase)."""
    return f"resume_{phase.value}"


DEBOUNCE_TICKS = 3
"""Ticks in a row a disagreement must last before the robot stops (and, after
the wait, before the program ends with an error)."""


def _readings(t: Tick, back: bool) -> tuple[float, float]:
    """The watched pair's readings (right, left), as the standing rule says them."""
    r, left = motion.pair(t.snap, back)
    return r.distance_m, left.distance_m


def _disagree(t: Tick, back: bool, raw_too: bool = True) -> bool:
    """Update the smoothed difference; True when it exceeds equal_tolerance
    (and, with ``raw_too``, the newest difference does as well)."""
    watch = t.ctx.watch
    diff = motion.pair_difference(t.snap, t.cfg, back)
    if diff is None:
        watch.diff = None
        return False
    watch.diff = motion.smooth(watch.diff, diff)
    right, left = motion.pair(t.snap, back)
    near = min(right.distance_m, left.distance_m)
    smoothed_tol = standing_tolerance(t.cfg, near, motion.DIFF_SMOOTHING, back)
    if back and back_apart.within(t, watch.diff, diff if raw_too else None):
        return False  # descent 2 goes on with the pair this far apart
    return abs(watch.diff) > smoothed_tol and \
        (not raw_too or abs(diff) > standing_tolerance(t.cfg, near, back=back))


def watch(t: Tick, phase: PhaseDef[Any]) -> Step | None:
    """In an armed phase: the Step that pauses the robot when the watched pair
    has disagreed long enough, else None.

    A continuous descent steers by the back pair alone (it squares up to
    each edge with it, and drives by turns): the front pair's rule is not
    armed.  On the top the front pair faces nothing, or a landing's walls
    (one beam on a side wall, the other open: a disagreement before the
    robot moves); below, risers the robot did not climb, which a cone
    sees over when they are low, and, in a flight 0.3 m wide, a side wall
    (ended on the stairs by a disagreement that steered nothing).  Nor is it
    armed in ascent 4 to 6 of a step the robot drives onto by turns (nothing
    ahead, or a tread past FAR_TREAD_M): the front pair steers nothing
    there, and pitched nose down in ascent 5 on the top step of a narrow
    flight it reads the floor ahead at a graze and a side wall, a
    disagreement about nothing it steers; ascent 7 reads the tab, and is
    armed."""
    if phase.watches is None:
        return None
    ctx = t.ctx
    back = phase.watches == "back"
    if ctx.from_top and not back:
        return None
    if not back and phase.phase in _BY_TURNS_ONTO and long_tread.near_length(t) is None:
        return None
    if not _disagree(t, back):
        ctx.watch.ticks = 0
        return None
    ctx.watch.ticks += 1
    if ctx.watch.ticks < DEBOUNCE_TICKS:
        return None
    return go(DISAGREE, say.disagree(back, _readings(t, back), phase.label,
                                     t.cfg.algorithm.standing_wait))


MEDIAN_S = 1.0
"""The end of the standing rule's wait: the median of the pair's difference
over its last this many seconds decides."""


def ended_median(diffs: list[float], snap: Snapshot, cfg: RobotConfig,
                 back: bool) -> float | None:
    """The median of ``diffs`` (the wait's last MEDIAN_S of ticks that gave a
    figure) if it lies beyond the smoothed standing tolerance at the pair's
    nearer reading now -- the pair still disagrees -- else None."""
    right, left = motion.pair(snap, back)
    near = min(right.distance_m, left.distance_m)
    median = statistics.median(diffs)
    return median if abs(median) > standing_tolerance(cfg, near, motion.DIFF_SMOOTHING,
                                                      back) else None


def ends_now(snap: Snapshot, ctx: Context, cfg: RobotConfig) -> float | None:
    """While the standing rule waits on the front pair: the median of the
    pair's difference (SFL less SFR) over the wait's last MEDIAN_S, if the
    rule ends the program on this tick (its own test, before its step runs:
    past the smoothed tolerance DEBOUNCE_TICKS ticks in a row, this the
    last); else None."""
    pause, diff = ctx.pause, motion.pair_difference(snap, cfg)
    if pause is None or diff is None or ctx.watch.ticks < DEBOUNCE_TICKS - 1:
        return None
    recent = [*pause.diffs, diff][-max(1, round(MEDIAN_S / cfg.algorithm.tick)):]
    return ended_median(recent, snap, cfg, False)


def _paused(t: Tick, _w: Work) -> Step:
    ctx, pause = t.ctx, t.ctx.pause
    assert pause is not None
    resume = Phase(pause.resume_phase).record
    back = resume.watches == "back"
    # Standing still, the difference over the wait decides, not one noisy tick
    # nor a smoothing that a burst at its end fills: the median of the wait's
    # last MEDIAN_S of ticks (two stray HC-SR04 measurements can pass a
    # sensor's median in the wait's last 0.2 s, and a smoothed difference
    # would then end a sound run).  A pair that gives no figure now
    # (nothing ahead, an error) does not disagree (as in _disagree); with
    # none on any tick, the smoothed difference decides.
    disagree = _disagree(t, back, raw_too=False)
    diff = motion.pair_difference(t.snap, t.cfg, back)
    if diff is not None:
        pause.diffs.append(diff)
        del pause.diffs[:-max(1, round(MEDIAN_S / t.cfg.algorithm.tick))]
    if t.snap.time_s - pause.started_s < t.cfg.algorithm.standing_wait:
        return stay(NO_MOTION)
    if diff is not None and pause.diffs:
        disagree = ended_median(pause.diffs, t.snap, t.cfg, back) is not None
    if not disagree:
        ctx.watch.ticks = 0
        lost = SensorStatus.ERROR in (r.status for r in motion.pair(t.snap, back))
        return go(resumed(resume.phase), say.no_figure(back, resume.label) if lost
                  else say.agree_again(back, _readings(t, back), resume.label))
    ctx.watch.ticks += 1
    if ctx.watch.ticks >= DEBOUNCE_TICKS:
        on = back_apart.goes_on(t, resume.phase, pause.diffs, resumed(resume.phase)) \
            if back else None
        if on is not None:
            ctx.watch.ticks = 0
            return on
        # the front pair, where the way home cannot do without it: why
        why = None if back else blind.why_not(resume.phase, ctx)
        return fail(say.still_disagree(back, t.cfg.algorithm.standing_wait, _readings(t, back),
                                       resume.label)
                    + ("" if why is None else say_limp.front_needed(why)))
    return stay(NO_MOTION)


PAUSED = PhaseDef(
    Phase.PAUSED, "standing rule — readings disagree: stopped, waiting", "end", _paused, Work,
    # the resumes, back to every armed phase, are added by the transition table
    on={FAILED: Exit(Phase.ERROR, "readings still disagree after standing_wait; " + FAULT)})

DONE = PhaseDef(Phase.DONE, "end — program finished", "end", None, Work)
ERROR = PhaseDef(Phase.ERROR, "end — program ended with an error", "end", None, Work)

PHASES: tuple[PhaseDef[Any], ...] = (PAUSED, DONE, ERROR)
