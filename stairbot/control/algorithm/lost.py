"""A sensor lost for good: the controller's decision when a sensor the phase
needs has read as ERROR for SENSOR_WAIT_S (:mod:`~stairbot.control.algorithm.limp`
says what limping home is).  The decision counts every distance sensor that
reads as ERROR then, needed by the phase or not (:func:`every_error`)."""

from __future__ import annotations

from collections.abc import Sequence

from stairbot.control.algorithm import blind, limp
from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.families import Calibration
from stairbot.control.algorithm.modes import AscentEnd, Purpose
from stairbot.control.algorithm.phase import Step, Tick, go, where
from stairbot.control.algorithm.phases import BY_VALUE, Mode, Phase
from stairbot.control.algorithm.texts import limp as say
from stairbot.hardware import BASE_SENSORS, SensorId, SensorStatus, Snapshot


def every_error(ctx: Context, snap: Snapshot, errors: Sequence[SensorId]) -> list[SensorId]:
    """``errors`` (the sensors the phase needs that read as ERROR), then every
    other distance sensor that reads as ERROR in ``snap`` (errors, stale,
    stuck, judged biased or distrusted) and is not lost already.  A sensor
    hold names them all, and waits for them all unless every one is judged;
    a degraded stop counts them all: the way home may need a sensor the
    present phase does not (the back pair, from ascent 7 of a step, finds
    the edges of the way down), and one that does not come back in the
    hold's wait is as lost as a sensor the phase needs."""
    known = ctx.limp.lost if ctx.limp is not None else ()
    sensors = snap.sensors
    return [*errors, *(s for s in BASE_SENSORS if s not in errors and s.value not in known
                       and sensors[s].status is SensorStatus.ERROR)]


def degraded_stop(ctx: Context, snap: Snapshot, phase: Phase, errors: Sequence[SensorId],
                  failed: str, *, mode: Mode, consent: bool, tilt_watched: bool,
                  biased: Sequence[SensorId] = ()) -> limp.DegradedStop | None:
    """What follows the loss of the sensors ``errors`` in ``phase`` (every
    distance sensor that reads as ERROR: :func:`every_error`; ``failed`` says
    what they report; ``biased``: those judged biased,
    :mod:`~stairbot.control.algorithm.bias`): None on the floor where the
    program began (the run ends on the sensor error, as it always has), else
    a degraded stop whose ``then`` says whether the robot limps home."""
    if phase is Phase.PAUSED and ctx.pause is not None:  # lost while the standing rule waits
        phase = BY_VALUE[ctx.pause.resume_phase]
    purpose = ctx.family.purpose if isinstance(ctx.family, Calibration) else None
    if limp.on_the_floor(phase, purpose, ctx.number_of_steps, mode,
                         began=ctx.start.home_wheel is not None):
        return None
    known = [SensorId(s) for s in ctx.limp.lost] if ctx.limp is not None else []
    lost = sorted(set(known) | set(errors), key=lambda s: s.value)
    front_why = blind.why_not(phase, ctx)
    why = limp.cannot_limp(lost, phase, purpose, tilt_watched,
                           turned_at_landing=ctx.landing.step is not None,
                           needs_no_front=front_why is None)
    if why is not None and front_why is not None and blind.unusable(set(lost)):
        why += f" ({front_why})"  # where the way home needs the front pair, why
    plan = "" if why is not None else _plan(ctx, phase, purpose, blind.unusable(set(lost)))
    if why is not None:
        then, told = "stranded", say.stranded(why)
    elif not consent:
        then, told = "no_consent", say.NO_CONSENT
    else:
        then, told = "limp_home", say.limping(plan, limp.survivors(lost), limp.LIMP_SPEED)
    return limp.DegradedStop(
        lost=tuple(s.value for s in lost), failed=failed, phase=phase.value,
        where=where(ctx, phase), steps_climbed=ctx.number_of_steps,
        steps_descended=ctx.steps_descended, lifts=limp.lifts(snap), then=then, why=told,
        survivors=limp.survivors(lost), plan=plan,
        biased=tuple(sorted(s.value for s in lost if s in biased)))


_UNDO = (Phase.ASCENT_LIFT_FIRST, Phase.ASCENT_LIFT_FIRST_MORE, Phase.ASCENT_LOWER_OBSTACLE)
_TURN_BACK = (Phase.ASCENT_APPROACH, Phase.ASCENT_APPROACH_TURNS)
_HOME = (Phase.DESCENT_FINISH, Phase.DESCENT_FINISH_FLOOR)
_HOME_PURPOSES = (Purpose.FLOOR, Purpose.HOME)


def _plan(ctx: Context, phase: Phase, purpose: Purpose | None, distrusted: bool) -> str:
    """What the limp home does from ``phase``, in words (``distrusted``: the
    front pair)."""
    if distrusted:
        if phase is Phase.ASCENT_DRIVE_FIRST:
            return say.UNDO_FIRST
        if phase is Phase.ASCENT_LOWER_OBSTACLE or phase in _HOME or purpose in _HOME_PURPOSES:
            return say.BY_THE_ODOMETER
        return say.FINISH_BLIND if phase.flow == "ascent" else say.DOWN_BLIND
    n = ctx.number_of_steps
    if ctx.ascent_end is not None or ctx.from_top or phase.flow == "descent" \
            or purpose not in (None, Purpose.START, Purpose.ASCENT):
        return say.plan("down", 0, 0)
    if phase in _UNDO:
        return say.plan("undo", n + 1, n)
    if phase in _TURN_BACK or purpose in (Purpose.ASCENT, Purpose.START):
        return say.plan("turn_back", n + 1, n)
    counted = phase in (Phase.ASCENT_CHECK, Phase.ASCENT_DRIVE_THIRD)
    return say.plan("finish", n if counted else n + 1, n if counted else n + 1)


def start_limping(ctx: Context, stop: limp.DegradedStop, time_s: float,
                  label: str) -> None:
    """Record in the context that the robot could limp home without the
    sensors ``stop`` lost: it does, or (``stop.then`` "no_consent") will
    once the operator consents (:func:`reopen`)."""
    consented = stop.then == "limp_home"
    if ctx.pause is not None:  # the standing rule's wait decides on the stand-in's figures
        ctx.pause.diffs.clear()
    if ctx.limp is None:
        at = f"{label} ({stop.where})" if stop.where else label
        ctx.limp = limp.Limp(list(stop.lost), time_s, at, consented,
                             "" if consented else ctx.phase)
    else:
        ctx.limp.lost = list(stop.lost)


def awaits_consent(ctx: Context) -> bool:
    """Whether the program ended on a degraded stop the robot could limp home
    from, had the operator consented."""
    return ctx.phase == Phase.ERROR.value and ctx.limp is not None \
        and not ctx.limp.consented and ctx.limp.stopped_in in BY_VALUE


def reopen(ctx: Context) -> bool:
    """Given the operator's consent now, a program ended on such a stop
    (:func:`awaits_consent`) goes on from the phase it stopped in, limping
    home; True if it does."""
    if not awaits_consent(ctx):
        return False
    assert ctx.limp is not None
    ctx.phase = ctx.limp.stopped_in
    ctx.outcome = ctx.error = ctx.end_reason = None
    ctx.limp.consented, ctx.limp.stopped_in = True, ""
    return True


LIMP = "a sensor lost on the stairs, limping home (consented)"
"""The condition of the exits a limp home takes, for the flowcharts."""


def limping(t: Tick) -> bool:
    """Whether the robot limps home: the ascent phases that turn it back
    (ascent 2 and 3 undo the step in progress, ascent 8 ends the ascent
    once it is done) end the ascent and say so, once."""
    ctx = t.ctx
    if ctx.limp is None:
        return False
    if ctx.ascent_end is None:
        ctx.ascent_end = AscentEnd.SENSOR_LOST
        t.say(say.limp_down(ctx.number_of_steps), ascent_end=AscentEnd.SENSOR_LOST.value)
    return True


def limp_down(t: Tick) -> Step:
    """Ascent 2 while limping home: down the steps climbed (descent 1), or,
    none climbed, back to the start (descent 7)."""
    return go("limp_home" if t.ctx.number_of_steps > 0 else "limp_home_floor")
