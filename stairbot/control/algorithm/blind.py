"""The front pair unusable: SFR and SFL still disagree at the end of the
standing rule's wait and no evidence names which of them reads wrong
(:mod:`~stairbot.control.algorithm.bias`).  Not in the seed.

Neither sensor is trusted then, and no guess is made at which is right:
both are lost (:mod:`~stairbot.control.algorithm.limp`), and the robot may
go on only where the rest of the way home needs no front reading:

* descent 7, on the floor after the last step, all wheels down: back to
  where the program began by the odometer (as when no step was climbed),
  turning by it to the floor's and the start's headings (calibration's
  lift, turn and lowering with a heading to turn to, ``Purpose.FLOOR`` or
  ``Purpose.HOME``);
* ascent 4 of the first step, the whole robot on the floor and segment 1
  lifted over the tread: the step undone by the odometer
  (:mod:`~stairbot.control.algorithm.undo_first`), segment 1 lowered again
  (ascent 3's obstacle phase), then descent 7 as above;
* ascent 5 to 8 of any step: the step finished by counts (the lifts by
  number_of_turns_for_step_height, ascent 6 by the seed's turns, as onto a
  long tread; ascent 7 stores no tab), then down it;
* descent 1 to 6 of a climbed step (:mod:`~stairbot.control.algorithm.blind_descent`):
  the back-off by the seed's turns, descent 1's calibration a turn back to
  the heading the step was climbed with by the odometer, the backing up to
  the edge by the back pair's edge watch alone (within the tread ascent 3
  measured), descent 3 and 5 by the seed's turns, the lifts by counts: a
  continuous descent's way down, the heading the odometer's.

Every reading drive goes by its turns from where it began
(:func:`~stairbot.control.algorithm.moves.reading_drive`).  Anywhere else (a
riser to square up to, a tread or a tab to read, a landing, a continuous
descent, a step climbed with no heading kept) the robot stays stopped,
lifts holding, and says why: stranded (:func:`why_not`).
"""

from __future__ import annotations

from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.families import Calibration
from stairbot.control.algorithm.modes import Purpose
from stairbot.control.algorithm.phases import BY_VALUE, Phase
from stairbot.hardware import FRONT_SENSORS, SensorId

_HOMING = frozenset({Phase.DESCENT_FINISH, Phase.DESCENT_FINISH_FLOOR})
"""Descent 7: on the floor, back to the start position."""
_TURNING_HOME = frozenset({Phase.CAL_LIFT, Phase.CAL_TURN_TO, Phase.CAL_LOWER})
"""Calibration's turn back to a heading by the odometer (in descent 7, and
in descent 1 to the heading the step was climbed with)."""
_HOME_PURPOSES = (Purpose.FLOOR, Purpose.HOME)
_UNDOING = frozenset({Phase.ASCENT_DRIVE_FIRST, Phase.ASCENT_LOWER_OBSTACLE})
"""Ascent 4 and ascent 3's lowering of segment 1: of the first step, undone."""
_FINISHING = frozenset({Phase.ASCENT_LIFT_SECOND, Phase.ASCENT_DRIVE_SECOND,
                        Phase.ASCENT_LIFT_THIRD, Phase.ASCENT_CHECK})
"""Ascent 5 to 8: the step finished by counts, then down it."""
_DESCENDING = frozenset({Phase.DESCENT_BACK_OFF, Phase.DESCENT_BACK_TO_EDGE,
                         Phase.DESCENT_LOWER_THIRD, Phase.DESCENT_DRIVE_SECOND,
                         Phase.DESCENT_LOWER_SECOND, Phase.DESCENT_DRIVE_FIRST,
                         Phase.DESCENT_LOWER_FIRST})
"""Descent 1 to 6 of a climbed step."""


def needs_no_front(phase: Phase, ctx: Context) -> bool:
    """Whether the robot can go on from ``phase`` (while the standing rule
    waits, the phase it stopped in) to the start without any front reading
    (see the module docstring)."""
    return why_not(phase, ctx) is None


def why_not(phase: Phase, ctx: Context) -> str | None:
    """Why the way home from ``phase`` needs a front reading (None: it does
    not): what a degraded stop with both front sensors lost tells."""
    if phase is Phase.PAUSED and ctx.pause is not None:
        phase = BY_VALUE[ctx.pause.resume_phase]
    if ctx.from_top:
        return "a continuous descent squares up to risers it did not climb"
    if ctx.landing.step is not None:
        return "across a landing's turn the front pair places the robot"
    if ctx.start.wheel is None:
        return "where the program began was not measured"
    if phase in _HOMING:
        return None
    if phase in _FINISHING:  # (ascent 7 counted the step before ascent 8)
        return _headings_unknown(ctx, ctx.number_of_steps
                                 - (1 if phase is Phase.ASCENT_CHECK else 0))
    if phase in _UNDOING:
        return None if ctx.number_of_steps == 0 else \
            "ascent 4 of a later step: the tread ahead is measured by the front pair"
    family = ctx.family if phase.flow == "calibration" else None
    if isinstance(family, Calibration) and family.purpose in _HOME_PURPOSES:
        return None if phase in _TURNING_HOME and family.turn_to is not None else \
            "squaring up to the riser"
    if phase in _DESCENDING or (isinstance(family, Calibration)
                                and family.purpose is Purpose.DESCENT):
        return _descent_why_not(phase, ctx)
    return f"{phase.label}: the front pair places the robot there"


_BY_ODOMETER_TURN = frozenset({Phase.CAL_LIFT, Phase.CAL_TURN_TO})
"""Descent 1's calibration: its lift and turn go on blind only towards a
heading (``turn_to``); its check and lowering go on always."""
_NO_TURN = frozenset({Phase.CAL_CHECK, Phase.CAL_LOWER})


def _descent_why_not(phase: Phase, ctx: Context) -> str | None:
    """Descent 1 to 6 of a climbed step, and descent 1's calibration: blind,
    the heading is the one the step was climbed with by the odometer, which
    must be known; calibration's own squaring turns read the front pair."""
    unknown = _headings_unknown(ctx, ctx.number_of_steps - ctx.steps_descended - 1)
    if unknown is not None:
        return unknown
    family = ctx.family
    if phase in _DESCENDING or phase in _NO_TURN:
        return None
    if phase in _BY_ODOMETER_TURN and isinstance(family, Calibration) \
            and family.turn_to is not None:
        return None
    return "in calibration's squaring turn, which reads the front pair"


def front_unusable(ctx: Context) -> bool:
    """Whether both front sensors are lost (the limp home goes on without
    them, where :func:`needs_no_front`)."""
    limp = ctx.limp
    return limp is not None and all(s.value in limp.lost for s in FRONT_SENSORS)


def unusable(lost: set[SensorId]) -> bool:
    """Whether ``lost`` holds both front sensors."""
    return all(s in lost for s in FRONT_SENSORS)


def _headings_unknown(ctx: Context, top: int) -> str | None:
    """Whether the heading each step from the first to ``top`` (0-based) was
    climbed with is known: blind, descent 1 of each turns back to it."""
    if top >= len(ctx.climb_twist):
        return f"the heading step {top + 1} was climbed with is not known"
    for i in range(top + 1):
        if ctx.climb_twist[i] is None:
            return f"the heading step {i + 1} was climbed with is not known"
    return None
