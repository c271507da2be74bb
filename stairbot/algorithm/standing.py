"""The standing rule: when the two sensors of a pair disagree, stop every
motor, wait standing_wait seconds on the controller's clock, measure again;
resume exactly where it stopped if they agree, end with an error if not.

Armed in the phases whose table entry lists :attr:`Phase.PAUSED` (where both
sensors of the pair look at the same flat surface), watching SBR/SBL in
descent 2 and SFR/SFL elsewhere.  A disagreement only counts when both sensors
give a usable distance, and both the difference and its smoothed value
(:data:`~stairbot.algorithm.motion.DIFF_SMOOTHING`) must exceed equal_tolerance for
DEBOUNCE_TICKS ticks in a row: neither a short spike nor sensor noise stops
the robot.
"""

from __future__ import annotations

from stairbot.algorithm import motion
from stairbot.algorithm.handler import Handler, PhaseIO, Speeds
from stairbot.algorithm.phases import Phase
from stairbot.algorithm.transitions import BACK_PAIR_PHASES, STANDING_ARMED
from stairbot.hardware import BACK_SENSORS, FRONT_SENSORS, SensorId

DEBOUNCE_TICKS = 3
"""Ticks in a row a disagreement must last before the robot stops (and, after
the wait, before the program ends with an error)."""


def watched(phase: Phase) -> tuple[SensorId, ...]:
    """The pair the standing rule watches in ``phase`` (empty: not armed)."""
    if phase not in STANDING_ARMED:
        return ()
    return BACK_SENSORS if phase in BACK_PAIR_PHASES else FRONT_SENSORS


def _pair_name(back: bool) -> str:
    return "SBR/SBL" if back else "SFR/SFL"


def _readings(io: PhaseIO, back: bool) -> str:
    r, left = motion.pair(io.snap, back)
    return f"{r.distance_m:.3f} m / {left.distance_m:.3f} m"


def _disagree(io: PhaseIO, back: bool, raw_too: bool = True) -> bool:
    """Update the smoothed difference; True when it exceeds equal_tolerance
    (and, with ``raw_too``, the newest difference does as well)."""
    ctx = io.ctx
    diff = motion.pair_difference(io.snap, io.cfg, back)
    if diff is None:
        ctx.standing_diff = None
        return False
    ctx.standing_diff = motion.smooth(ctx.standing_diff, diff)
    tol = io.cfg.algorithm.equal_tolerance
    return abs(ctx.standing_diff) > tol and (not raw_too or abs(diff) > tol)


def watch(io: PhaseIO) -> bool:
    """Apply the rule in an armed phase; True when it has just stopped the robot."""
    phase = io.phase
    if phase not in STANDING_ARMED:
        return False
    ctx = io.ctx
    back = phase in BACK_PAIR_PHASES
    if not _disagree(io, back):
        ctx.disagree_ticks = 0
        return False
    ctx.disagree_ticks += 1
    if ctx.disagree_ticks < DEBOUNCE_TICKS:
        return False
    ctx.disagree_ticks = 0
    ctx.resume_phase = phase.value
    ctx.pause_started_s = io.snap.time_s
    ctx.pauses += 1
    io.machine.pause(f"standing rule: {_pair_name(back)} disagree ({_readings(io, back)}) in "
                     f"{phase.label}: all motors stopped, measuring again in "
                     f"{io.cfg.algorithm.standing_wait:g} s", io.snap)
    return True


def _paused(io: PhaseIO) -> Speeds:
    ctx = io.ctx
    assert ctx.resume_phase is not None and ctx.pause_started_s is not None
    resume = Phase(ctx.resume_phase)
    back = resume in BACK_PAIR_PHASES
    # Standing still, the smoothed difference alone decides: it has been kept up
    # to date through the wait, and one noisy tick must not decide either way.
    disagree = _disagree(io, back, raw_too=False)
    if io.snap.time_s - ctx.pause_started_s < io.cfg.algorithm.standing_wait:
        return {}
    if not disagree:
        ctx.disagree_ticks = 0
        io.machine.resume(f"standing rule: {_pair_name(back)} agree again "
                          f"({_readings(io, back)}): resuming {resume.label}", io.snap)
        return {}
    ctx.disagree_ticks += 1
    if ctx.disagree_ticks >= DEBOUNCE_TICKS:
        io.fail(f"standing rule: {_pair_name(back)} still disagree after "
                f"{io.cfg.algorithm.standing_wait:g} s ({_readings(io, back)}) in {resume.label}")
    return {}


HANDLERS: dict[Phase, Handler] = {Phase.PAUSED: Handler(_paused)}
