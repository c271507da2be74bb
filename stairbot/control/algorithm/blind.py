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
  (ascent 3's obstacle phase), then descent 7 as above.

Anywhere else (a riser to square up to, a tread or a tab to read) the robot
stays stopped, lifts holding, and says why: stranded, as before.
"""

from __future__ import annotations

from stairbot.control.algorithm import motion, standing
from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.families import Calibration
from stairbot.control.algorithm.modes import Purpose
from stairbot.control.algorithm.phases import BY_VALUE, Phase
from stairbot.hardware import FRONT_SENSORS, SensorId, Snapshot
from stairbot.inputs.config import RobotConfig

_HOMING = frozenset({Phase.DESCENT_FINISH, Phase.DESCENT_FINISH_FLOOR})
"""Descent 7: on the floor, back to the start position."""
_TURNING_HOME = frozenset({Phase.CAL_LIFT, Phase.CAL_TURN_TO, Phase.CAL_LOWER})
"""Calibration's turn back to a heading by the odometer (in descent 7)."""
_HOME_PURPOSES = (Purpose.FLOOR, Purpose.HOME)
_UNDOING = frozenset({Phase.ASCENT_DRIVE_FIRST, Phase.ASCENT_LOWER_OBSTACLE})
"""Ascent 4 and ascent 3's lowering of segment 1: of the first step, undone."""


def needs_no_front(phase: Phase, ctx: Context) -> bool:
    """Whether the robot can go on from ``phase`` (while the standing rule
    waits, the phase it stopped in) to the start without any front reading
    (see the module docstring)."""
    if phase is Phase.PAUSED and ctx.pause is not None:
        phase = BY_VALUE[ctx.pause.resume_phase]
    if ctx.from_top or ctx.landing.step is not None or ctx.start.wheel is None:
        return False
    if phase in _HOMING:
        return True
    if phase in _UNDOING:
        return ctx.number_of_steps == 0
    family = ctx.family
    return phase in _TURNING_HOME and isinstance(family, Calibration) \
        and family.purpose in _HOME_PURPOSES and family.turn_to is not None


def front_unusable(ctx: Context) -> bool:
    """Whether both front sensors are lost (the limp home goes on without
    them, where :func:`needs_no_front`)."""
    limp = ctx.limp
    return limp is not None and all(s.value in limp.lost for s in FRONT_SENSORS)


def unusable(lost: set[SensorId]) -> bool:
    """Whether ``lost`` holds both front sensors."""
    return all(s in lost for s in FRONT_SENSORS)


def ends_now(snap: Snapshot, ctx: Context, cfg: RobotConfig) -> float | None:
    """While the standing rule waits on the front pair: the median of the
    pair's difference (SFL less SFR) over the wait's last MEDIAN_S, if the
    rule ends the program on this tick (its own test, before its step runs:
    past the smoothed tolerance DEBOUNCE_TICKS ticks in a row, this the
    last); else None."""
    pause, diff = ctx.pause, motion.pair_difference(snap, cfg)
    if pause is None or diff is None or ctx.watch.ticks < standing.DEBOUNCE_TICKS - 1:
        return None
    recent = [*pause.diffs, diff][-max(1, round(standing.MEDIAN_S / cfg.algorithm.tick)):]
    return standing.ended_median(recent, snap, cfg, False)
