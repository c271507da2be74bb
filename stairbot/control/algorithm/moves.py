"""The shapes of phase several steps of the seed share: a drive that ends at a
reading (with the seed's turn-count fallback), and lifts to counter targets.

Each builder returns the (enter, step) pair of a :class:`PhaseDef`; ``done``
chooses the :class:`Step` that ends the phase (what happened: usually
``go("reached")``).  :func:`drive_phase` and :func:`lift_phase` build the
whole record of the plainest ones, which end on one outcome, "reached" and
"turns_made", leading to one next phase (the ascent's and descent's mirrored
drives and lifts of segments 1 and 2).
"""

from __future__ import annotations

import statistics
from collections.abc import Callable
from typing import Protocol, TypeVar

from stairbot.control.algorithm import blind, motion
from stairbot.control.algorithm.phase import (
    FAILED,
    FAULT,
    NO_MOTION,
    Exit,
    Phase,
    PhaseDef,
    Step,
    Tick,
    go,
    stay,
)
from stairbot.control.algorithm.texts import shared as say
from stairbot.control.algorithm.work import DriveWork, LiftWork, Work
from stairbot.control.tolerances import median_sigma
from stairbot.hardware import MotorId
from stairbot.inputs.config import RobotConfig

W = TypeVar("W", bound=Work)
D = TypeVar("D", bound=DriveWork)
L = TypeVar("L", bound=LiftWork)
Enter = Callable[[Tick, W], None]
StepFn = Callable[[Tick, W], Step]
Done = Callable[[Tick, W], Step]


JUMP_M = 0.02
"""A reading drive trusts its reading while it stays within this (or JUMP_SIGMAS
of the filtered reading's sigma, if more) of what the wheels explain."""
JUMP_SIGMAS = 6.0
KEY_TICKS = 5
"""The surface a reading drive starts on is the median of its first this many
ticks' readings (less what the wheels drove), not of the first alone: that
may be a stray (an outlier just after the pair came into range)."""
RISER_KEYS = 15
"""Ascent 2 places the riser by the median of this many ticks' readings
(plus the odometer), once it has KEY_TICKS of them."""


def jump_limit(cfg: RobotConfig, distance_m: float) -> float:
    """How far a drive's reading may stray from its odometry and still be the
    surface it started on."""
    return max(JUMP_M, JUMP_SIGMAS * median_sigma(cfg, False, distance_m))


def reading_drive(
    direction: int,
    target: Callable[[Tick], float | None],
    fallback_turns: Callable[[Tick], float],
    done: Done[D],
    bound: Callable[[Tick, D], float | None] | None = None,
    exact: bool = False,
) -> tuple[Enter[D], StepFn[D]]:
    """A drive (``direction`` +1 forward, -1 back) that ends when the mean
    SFR/SFL reading reaches ``target(t)`` metres.

    While the front sensors are measurable the target is re-expressed as an
    absolute wheel-counter target every tick (dead reckoning from the median
    of its last KEY_TICKS readings, each less what the wheels drove since);
    while they are not, the drive carries on to the last such target — or,
    if they never were, to ``fallback_turns(t)`` turns from the phase's start
    (the seed's "not measurable" fallback).  A ``target`` of
    None means a drive by turns only, and so does a front pair distrusted
    (:func:`~stairbot.control.algorithm.blind.front_unusable`): then the
    drive goes ``fallback_turns(t)`` from the phase's start, whatever its
    readings gave before.  ``bound(t, w)``, when it gives one, is
    a wheel-counter position the drive never passes, whatever the readings say;
    with ``exact``, the position it ends at.
    """

    def enter(t: Tick, w: D) -> None:
        w.target_reading = None if blind.front_unusable(t.ctx) else target(t)
        w.target_wheel = w.entry_wheel + direction * fallback_turns(t)

    def step(t: Tick, w: D) -> Step:
        cfg = t.cfg
        here = motion.wheel_position(t.snap)
        if w.target_reading is not None and blind.front_unusable(t.ctx):
            # the front pair distrusted (:mod:`~stairbot.control.algorithm.blind`):
            # no target its readings gave stands, the drive goes by its turns
            # from where it began
            w.target_reading = None
            w.target_wheel = w.entry_wheel + direction * fallback_turns(t)
        if w.target_reading is not None and not w.reading_lost \
                and motion.measurable(t.snap, cfg):
            reading = motion.mean_distance(t.snap)
            key = reading + here * cfg.wheel_circumference
            if len(w.first_keys) < KEY_TICKS:
                w.first_keys.append(key)
                w.reading_key = statistics.median(w.first_keys)
            assert w.reading_key is not None
            jump = key - w.reading_key
            if len(w.first_keys) >= KEY_TICKS and abs(jump) > jump_limit(cfg, reading):
                # Not the surface the drive started on (the beams slid over an
                # edge, or onto a side wall): the wheels carry on to the last
                # target the readings gave.
                w.reading_lost = True
                t.say(say.reading_jumped(jump, reading), jump=jump)
            else:
                # The target from the median of the last KEY_TICKS keys, not
                # from this tick's reading alone: two stray HC-SR04
                # measurements in three pass perception's median on a tick,
                # and a target set by it can be centimetres short; lowered
                # on the step's edge there, segment 1 pitches the robot nose up.
                recent = w.recent_keys
                recent.append(key)
                if len(recent) > KEY_TICKS:
                    del recent[0]
                surface = recent[0] if len(recent) == 1 else statistics.median(recent)
                remaining_m = direction * (surface - key + reading - w.target_reading)
                w.target_wheel = here + direction * cfg.wheel_turns(remaining_m)
        assert w.target_wheel is not None  # set on entry
        limit = None if bound is None else bound(t, w)
        if limit is not None and (exact or direction * (w.target_wheel - limit) > 0):
            w.target_wheel = limit
        remaining = direction * (w.target_wheel - here)
        if remaining <= motion.WHEEL_DONE:
            if limit is None and w.target_reading is not None and not w.reading_lost \
                    and 0 < len(w.first_keys) < KEY_TICKS:
                # Ended by its first ticks' readings: stand until KEY_TICKS of
                # them agree.  One stray far reading at its start would end
                # the drive at once, and lowered on the step's edge there,
                # segment 1 pitches the robot nose up.
                return stay(NO_MOTION)
            return done(t, w)
        return stay(motion.drive(cfg, direction, remaining))

    return enter, step


def turns_drive(direction: int, turns: Callable[[Tick], float],
                done: Done[D]) -> tuple[Enter[D], StepFn[D]]:
    """A drive of ``turns(t)`` wheel turns (``direction`` +1 forward, -1 back)."""
    return reading_drive(direction, lambda _t: None, turns, done)


def lift(deltas: Callable[[Tick, L], dict[MotorId, float]],
         done: Done[L]) -> tuple[Enter[L], StepFn[L]]:
    """Lifts to absolute counters, all at once: ``deltas(t, w)`` on entry gives
    them relative to the entry counters, as {MTF: delta, MTB: delta}."""

    def enter(t: Tick, w: L) -> None:
        d = deltas(t, w)
        w.target_mtf = w.entry_mtf + d[MotorId.MTF] if MotorId.MTF in d else None
        w.target_mtb = w.entry_mtb + d[MotorId.MTB] if MotorId.MTB in d else None

    def step(t: Tick, w: L) -> Step:
        speeds = motion.lifts_to(t.cfg, t.snap, w.lift_targets())
        if speeds is None:
            return done(t, w)
        return stay(speeds)

    return enter, step


class Still(Protocol):
    """A work that keeps when the robot stopped to stand still."""

    still_since: float | None


def stood(t: Tick, w: Still, seconds: float) -> bool:
    """Standing still since ``w.still_since`` (set now if unset) for
    ``seconds`` (a filter's settling time)."""
    if w.still_since is None:
        w.still_since = t.snap.time_s
    return t.snap.time_s - w.still_since >= seconds - 1e-9  # (clocks round alike)


def checked_first(check: Callable[[Tick, W], Step | None], step: StepFn[W]) -> StepFn[W]:
    """``step``, with ``check`` run once before its first tick: a phase whose
    entry condition does not hold ends there (``check`` returns that Step)
    before anything moves."""

    def first(t: Tick, w: W) -> Step:
        if not w.checked:
            w.checked = True
            stop = check(t, w)
            if stop is not None:
                return stop
        return step(t, w)

    return first


def drive_phase(phase: Phase, label: str, flow: str, direction: int,
                target: Callable[[Tick], float | None],
                fallback_turns: Callable[[Tick], float], then: Phase, reaches: str,
                done: Done[D] | None = None,
                bound: Callable[[Tick, D], float | None] | None = None, *,
                work: type[D]) -> PhaseDef[D]:
    """A :func:`reading_drive` phase whose outcome "reached" (it ``reaches``
    its target) leads to ``then`` (``done``, if given, records what the end
    tells first, and returns that Step; ``bound`` as the drive's); the front
    pair is watched; ``work``: the phase's work (a DriveWork)."""
    enter, step = reading_drive(direction, target, fallback_turns,
                                done or (lambda _t, _w: go("reached")), bound)
    return PhaseDef(phase, label, flow, step, work, enter=enter, watches="front",
                    on={"reached": Exit(then, reaches), FAILED: Exit(Phase.ERROR, FAULT)})


def lift_phase(phase: Phase, label: str, flow: str,
               deltas: Callable[[Tick, LiftWork], dict[MotorId, float]], then: Phase,
               carried_by: tuple[int, ...]) -> PhaseDef[LiftWork]:
    """A :func:`lift` phase whose outcome "turns_made" leads to ``then``, the
    robot carried by the wheels of the segments ``carried_by``; the front pair
    is watched."""
    enter, step = lift(deltas, lambda _t, _w: go("turns_made"))
    return PhaseDef(phase, label, flow, step, LiftWork, enter=enter, watches="front",
                    carried_by=carried_by,
                    on={"turns_made": Exit(then, "turns made"), FAILED: Exit(Phase.ERROR, FAULT)})
