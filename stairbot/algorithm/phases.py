"""The controller's phases: one for every step and sub-step of the seed.

Each :class:`Phase` carries the label the seed would use for it (shown to the
operator, e.g. "ascent 3 — lift segment 1") and the flow it belongs to:
``"calibration"``, ``"ascent"``, ``"descent"``, or ``"end"`` for the phases that
stand outside the three flowcharts (the standing rule's wait, done, error).
The calibration phases serve three purposes (the start of the program, ascent
step 1 on later steps, descent step 1); the context says which.
"""

from __future__ import annotations

from enum import Enum


class Mode(Enum):
    """What a run does: the whole program, or only the first calibration."""

    FULL = "full"
    CALIBRATE_ONLY = "calibrate_only"


class Phase(Enum):
    """A phase of the algorithm; ``value`` is a stable name for logs and JSON."""

    CAL_CHECK = "cal_check"
    CAL_LIFT = "cal_lift"
    CAL_TURN = "cal_turn"
    CAL_PROBE = "cal_probe"
    CAL_CORNER = "cal_corner"
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
    DESCENT_DRIVE_SECOND = "descent_drive_second"
    DESCENT_LOWER_SECOND = "descent_lower_second"
    DESCENT_DRIVE_FIRST = "descent_drive_first"
    DESCENT_LOWER_FIRST = "descent_lower_first"
    DESCENT_FINISH = "descent_finish"
    PAUSED = "paused"
    DONE = "done"
    ERROR = "error"

    @property
    def label(self) -> str:
        """The phase as the seed names it, e.g. "ascent 3 — lift segment 1"."""
        return _LABELS[self][0]

    @property
    def flow(self) -> str:
        """"calibration", "ascent", "descent" or "end"."""
        return _LABELS[self][1]

    @property
    def terminal(self) -> bool:
        """True for the phases a run ends in."""
        return self in (Phase.DONE, Phase.ERROR)

    def __str__(self) -> str:
        return self.label


_LABELS: dict[Phase, tuple[str, str]] = {
    Phase.CAL_CHECK: ("calibration — check the readings (case 1?)", "calibration"),
    Phase.CAL_LIFT: ("calibration — lift segments 1 and 3 for clearance", "calibration"),
    Phase.CAL_TURN: ("calibration case 2 — turn until SFR = SFL", "calibration"),
    Phase.CAL_PROBE: ("calibration case 3 — probe turn left (A or B?)", "calibration"),
    Phase.CAL_CORNER: ("calibration case 3B — turn left until both readings shrink", "calibration"),
    Phase.CAL_LOWER: ("calibration — lower segments 1 and 3", "calibration"),
    Phase.ASCENT_APPROACH: ("ascent 2 — approach to SAFE_DISTANCE_IN_FRONT_OF_STEP", "ascent"),
    Phase.ASCENT_APPROACH_TURNS: (
        "ascent 2 — approach: NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH more", "ascent"),
    Phase.ASCENT_LIFT_FIRST: ("ascent 3 — lift segment 1", "ascent"),
    Phase.ASCENT_LIFT_FIRST_MORE: (
        "ascent 3 — lift segment 1: number_of_vertical_turns more", "ascent"),
    Phase.ASCENT_LOWER_OBSTACLE: ("ascent 3 — step too high: lower segment 1", "ascent"),
    Phase.ASCENT_DRIVE_FIRST: ("ascent 4 — drive segment 1 onto the step", "ascent"),
    Phase.ASCENT_LIFT_SECOND: ("ascent 5 — lift segment 2", "ascent"),
    Phase.ASCENT_DRIVE_SECOND: ("ascent 6 — drive segment 2 onto the step", "ascent"),
    Phase.ASCENT_LIFT_THIRD: ("ascent 7 — lift segment 3", "ascent"),
    Phase.ASCENT_CHECK: ("ascent 8 — check the distance (top?)", "ascent"),
    Phase.ASCENT_DRIVE_THIRD: ("ascent 9 — drive segment 3 onto the step", "ascent"),
    Phase.DESCENT_BACK_OFF: ("descent 1 — back off to a safe position", "descent"),
    Phase.DESCENT_BACK_TO_EDGE: ("descent 1 — back up to the edge", "descent"),
    Phase.DESCENT_LOWER_THIRD: ("descent 2 — lower segment 3", "descent"),
    Phase.DESCENT_DRIVE_SECOND: ("descent 3 — drive segment 2 off the step", "descent"),
    Phase.DESCENT_LOWER_SECOND: ("descent 4 — lower segment 2", "descent"),
    Phase.DESCENT_DRIVE_FIRST: ("descent 5 — drive segment 1 off the step", "descent"),
    Phase.DESCENT_LOWER_FIRST: ("descent 6 — lower segment 1", "descent"),
    Phase.DESCENT_FINISH: ("descent 7 — finish: back off to the start position", "descent"),
    Phase.PAUSED: ("standing rule — readings disagree: stopped, waiting", "end"),
    Phase.DONE: ("end — program finished", "end"),
    Phase.ERROR: ("end — program ended with an error", "end"),
}

BY_VALUE: dict[str, Phase] = {p.value: p for p in Phase}
"""Phase by its value (faster than ``Phase(value)`` in the control tick)."""

FLOWS: tuple[str, ...] = ("calibration", "ascent", "descent")
"""The flows drawn as flowcharts, in order."""
