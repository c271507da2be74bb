"""The controller's phases: one for every step and sub-step of the seed.

A :class:`Phase` is the phase's identity (its ``value`` is the stable name in
logs and JSON); everything else about it is its record
(:class:`~stairbot.control.algorithm.phase.PhaseDef`, in the module of its flow): the
label the seed would use for it (shown to the operator, e.g. "ascent 3 — lift
segment 1"), the flow it belongs to (``"calibration"``, ``"ascent"``,
``"descent"``, or ``"end"`` for the standing rule's wait, done, error), its
entry action, its step and its transitions.
The calibration phases serve three purposes (the start of the program, ascent
step 1 on later steps, descent step 1); the context says which.
"""

from __future__ import annotations

from collections.abc import Mapping
from enum import Enum
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from stairbot.control.algorithm.phase import PhaseDef


class Mode(Enum):
    """What a run does: the whole program, or only the first calibration."""

    FULL = "full"
    CALIBRATE_ONLY = "calibrate_only"
    DESCEND = "descend"
    """Continuous descent: the robot stands on the top of a flight it has not
    climbed, facing away from it, and backs down it step by step until the
    floor."""

    @classmethod
    def for_start(cls, on: str) -> Mode:
        """The whole program for a robot that starts ``on`` "floor" or "top"
        (a scenario's ``start.on``)."""
        return cls.DESCEND if on == "top" else cls.FULL


class Phase(Enum):
    """A phase of the algorithm; ``value`` is a stable name for logs and JSON."""

    CAL_CHECK = "cal_check"
    CAL_CLOSE_IN = "cal_close_in"
    CAL_LIFT = "cal_lift"
    CAL_TURN = "cal_turn"
    CAL_TURN_TO = "cal_turn_to"
    CAL_PROBE = "cal_probe"
    CAL_CORNER = "cal_corner"
    CAL_AWAY = "cal_away"
    CAL_LOWER = "cal_lower"
    ASCENT_APPROACH = "ascent_approach"
    ASCENT_APPROACH_TURNS = "ascent_approach_turns"
    ASCENT_LIFT_FIRST = "ascent_lift_first"
    ASCENT_LIFT_FIRST_MORE = "ascent_lift_first_more"
    ASCENT_LOWER_OBSTACLE = "ascent_lower_obstacle"
    ASCENT_DRIVE_FIRST = "ascent_drive_first"
    ASCENT_LIFT_SECOND = "ascent_lift_second"
    ASCENT_DRIVE_SECOND = "ascent_drive_second"
    ASCENT_LIFT_THIRD = "ascent_lift_third"
    ASCENT_CHECK = "ascent_check"
    ASCENT_DRIVE_THIRD = "ascent_drive_third"
    DESCENT_BACK_OFF = "descent_back_off"
    DESCENT_BACK_TO_EDGE = "descent_back_to_edge"
    DESCENT_LOWER_THIRD = "descent_lower_third"
    DESCENT_REFUSE = "descent_refuse"
    DESCENT_DRIVE_SECOND = "descent_drive_second"
    DESCENT_LOWER_SECOND = "descent_lower_second"
    DESCENT_DRIVE_FIRST = "descent_drive_first"
    DESCENT_LOWER_FIRST = "descent_lower_first"
    DESCENT_FINISH = "descent_finish"
    DESCENT_FINISH_FLOOR = "descent_finish_floor"
    LANDING_SCAN = "landing_scan"
    LANDING_SCAN_LOWER = "landing_scan_lower"
    LANDING_CENTRE = "landing_centre"
    LANDING_RETURN = "landing_return"
    PAUSED = "paused"
    DONE = "done"
    ERROR = "error"

    @property
    def record(self) -> PhaseDef[Any]:
        """The phase's record: seed name, flow, entry action, step, transitions."""
        return _records()[self]

    @property
    def label(self) -> str:
        """The phase as the seed names it, e.g. "ascent 3 — lift segment 1"."""
        return _records()[self].label

    @property
    def flow(self) -> str:
        """"calibration", "ascent", "descent" or "end"."""
        return _records()[self].flow

    @property
    def terminal(self) -> bool:
        """True for the phases a run ends in."""
        return self in _ENDS

    def __str__(self) -> str:
        return self.label


_RECORDS: dict[Phase, PhaseDef[Any]] = {}
"""Every phase's record.  The records live with their flows (calibration.py,
ascent.py...), which import this module: this module imports none of them.
:mod:`~stairbot.control.algorithm.table` gathers them and binds them here
(:func:`bind`) when it is imported, and the package imports it first."""


def bind(records: Mapping[Phase, PhaseDef[Any]]) -> None:
    """Make ``records`` the phases' records (the table does, once)."""
    missing = set(Phase) - set(records)
    if missing:
        raise RuntimeError(f"phases without a record: {sorted(p.value for p in missing)}")
    _RECORDS.update(records)


def _records() -> dict[Phase, PhaseDef[Any]]:
    return _RECORDS


_ENDS = (Phase.DONE, Phase.ERROR)
"""The phases a run ends in (bound once: the control tick asks every tick)."""

BY_VALUE: dict[str, Phase] = {p.value: p for p in Phase}
"""Phase by its value (faster than ``Phase(value)`` in the control tick)."""

FLOWS: tuple[str, ...] = ("calibration", "ascent", "descent")
"""The flows drawn as flowcharts, in order."""
