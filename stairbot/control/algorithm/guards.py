"""What the controller checks whatever the phase decides: how long a phase
may last, which sensors a phase needs (a sensor that reads as ERROR stands
the robot, and ends the program if it lasts), what the link lost during such
a hold, and that a restored context's state is its phase's.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from stairbot.control.algorithm import blind, motion, squaring
from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.phases import BY_VALUE, Phase
from stairbot.control.algorithm.transitions import BACK_PAIR_PHASES
from stairbot.errors import InputError
from stairbot.hardware import (
    BACK_SENSORS,
    BASE_SENSORS,
    FRONT_SENSORS,
    LIFT_MOTORS,
    MotorId,
    SensorId,
    SensorStatus,
    Snapshot,
    Speeds,
)
from stairbot.inputs.config import RobotConfig

SENSOR_WAIT_S = 1.0
"""How long the robot stands, lifts holding, for a sensor it needs that reads
as ERROR (errors, or stale) to come back before the program ends with the
error."""

PHASE_TIMEOUT_S = 60.0
"""A phase (other than the standing rule's wait) that lasts longer than this,
in controller time, ends the program with an error: something is stuck.  A
robot with slow motors gets longer: :func:`phase_timeout_s`."""


def phase_timeout_s(config: RobotConfig) -> float:
    """How long one phase may last: twice the longest motion a phase makes at
    the config's speeds (a lift over its whole stroke, a drive of
    LENGTH_OF_INFINITY, a calibration turn of its largest yaw), and at least
    PHASE_TIMEOUT_S."""
    m = config.motors
    lift_s = 2 * config.MAX_OF_VERTICAL_TURNS / m.lift_speed
    drive_s = config.wheel_turns(config.LENGTH_OF_INFINITY) / m.wheel_speed
    turn = squaring.MAX_TURN_YAW_RAD * config.geometry.track_width / 2
    turn_s = config.wheel_turns(turn) / min(motion.TURN_SPEED, m.wheel_speed)
    return max(PHASE_TIMEOUT_S, 2 * max(lift_s, drive_s, turn_s))

def fault(snap: Snapshot, phase: Phase, needed: tuple[SensorId, ...],
          started_s: float | None, timeout_s: float) -> str | None:
    """A motor fault, a sensor ``needed`` that reads no number, or the
    phase (begun at ``started_s``) lasting longer than ``timeout_s``, in
    words; None when there is none."""
    isfinite = math.isfinite
    for motor, state in snap.motors.items():
        if state.fault:
            return f"motor fault: {motor} reports {state.fault!r} in {phase.label}"
        if not isfinite(state.turns):
            return f"motor fault: {motor} counts {state.turns} turns in {phase.label}"
    sensors = snap.sensors
    for sensor in needed:
        # an ERROR reading's distance means nothing; any other must be a number
        reading = sensors[sensor]
        if reading.status is not _ERROR and not isfinite(reading.distance_m):
            return f"sensor error: {sensor} reads {reading.distance_m} m in {phase.label}"
    if phase is not _PAUSED and started_s is not None and snap.time_s - started_s > timeout_s:
        return f"phase timeout: {phase.label} took longer than {timeout_s:g} s"
    return None


def limit_speeds(speeds: Speeds, snap: Snapshot, vmax: Mapping[MotorId, float],
                 stroke: float) -> dict[MotorId, float]:
    """Every motor gets a speed within its ``vmax``; a lift at the end of its
    ``stroke`` is not driven further."""
    isfinite = math.isfinite
    out = _ZEROS.copy()
    for motor, v in speeds.items():
        top = vmax[motor]
        # min/max pass a NaN through as a full-speed limit: it stops instead
        # (max(-top, min(top, v)), written out: the same answer, without the calls)
        if isfinite(v):
            v = v if v < top else top
            v = v if v > -top else -top
        else:
            v = 0.0
        if motor in LIFT_MOTORS:
            turns = snap.motors[motor].turns
            if (v > 0 and turns >= stroke) or (v < 0 and turns <= -stroke):
                v = 0.0
        out[motor] = v
    return out


# bound once: looked at every tick (an enum's member is a slow look-up, iterating
# the enum slower still)
_PAUSED, _ERROR = Phase.PAUSED, SensorStatus.ERROR
_ZEROS: dict[MotorId, float] = dict.fromkeys(MotorId, 0.0)


def check_restored(ctx: Context) -> None:
    """A restored context's work and family are the present phase's kinds
    (while the standing rule waits, the phase it resumes); InputError naming
    the key when not."""
    phase = BY_VALUE[ctx.phase]
    if phase is Phase.PAUSED and ctx.pause is not None:
        phase = BY_VALUE[ctx.pause.resume_phase]
    if phase.terminal:
        return
    record = phase.record
    if type(ctx.work) is not record.work:
        raise InputError("context", "work.kind", f"{ctx.work.KIND} is not the work of "
                         f"{phase.value} ({record.work.KIND})")
    if record.family is not None and type(ctx.family) is not record.family:
        raise InputError("context", "family.kind", f"{type(ctx.family).__name__} is not the "
                         f"family of {phase.value} ({record.family.__name__})")


def needed_sensors(phase: Phase, ctx: Context) -> tuple[SensorId, ...]:
    """The sensors whose ERROR status (errors, or stale) stands the robot in
    ``phase``, and ends the program if it lasts.  What it reads of ``ctx``
    (the steps climbed and come down, the lost, a pause) changes only with
    the phase or the lost, when the controller asks again."""
    if phase is Phase.PAUSED and ctx.pause is not None:
        phase = Phase(ctx.pause.resume_phase)
    if phase.terminal:
        return ()
    if blind.front_unusable(ctx) and blind.needs_no_front(phase, ctx):
        # the front pair distrusted: the back pair still finds the edge and the
        # floor below; elsewhere the way home goes by the odometer
        return BACK_SENSORS if phase in _EDGE_WATCH or phase in BACK_PAIR_PHASES else ()
    if ctx.from_top and phase.flow != "ascent":
        return BACK_SENSORS  # a continuous descent steers by the back pair alone
    if phase in _EDGE_WATCH:
        return BASE_SENSORS
    if phase is Phase.LANDING_SCAN:
        # The scan moves segment 3 alone, and steers nothing: a side pair that
        # reads no distance there is no flight (the landing is refused, the
        # robot goes home), not a reason to end the program on the landing.
        return ()
    if phase.flow == "ascent" or ctx.number_of_steps > ctx.steps_descended:
        # From the approach until the last step is come down, the way home
        # needs both pairs (the front reads the risers and treads, the back
        # finds each edge): a sensor lost where the phase reads only the
        # other pair stands the robot there, not a step or a flight later
        # where it is read.  On the floor at either end the phase's own.
        return BASE_SENSORS
    return BACK_SENSORS if phase in BACK_PAIR_PHASES else FRONT_SENSORS


_EDGE_WATCH = frozenset({Phase.DESCENT_BACK_OFF, Phase.DESCENT_BACK_TO_EDGE})
"""Descent 1's phases watch the back pair for the edge as they back: a back
sensor that reports errors, or stops measuring, would hide it (the edge is
where both read the drop), and backing from the top of a flight the robot
would go over the edge unseen."""


LINK_TROUBLE = ("retries", "timeouts", "lost", "revived")
"""The link figures (Snapshot.health) that say frames went missing."""


def link_meanwhile(before: Mapping[str, float], now: Mapping[str, float],
                   consequence: str = "") -> str:
    """What the link counted between two of its figures (a sensor hold, a
    phase), when it lost frames, and ``consequence`` after a colon: a reading
    goes stale, and a phase runs long, on a wire that loses frames, and the
    error says so (empty for a robot with no link, or a link that lost nothing)."""
    grown = {k: now[k] - before.get(k, 0.0) for k in LINK_TROUBLE if k in now}
    if not any(v > 0 for v in grown.values()):
        return ""
    counts = ", ".join(f"{v:.0f} {k}" for k, v in grown.items() if v > 0)
    tail = f": {consequence}" if consequence else ""
    return f"; meanwhile the link lost frames ({counts}){tail}"
