"""What each phase does, in the operator's words: the phase panel shows
these first and the seed's own label (``ascent 3 — lift segment 1``)
beneath, dimmer.  Segments are numbered front to back, as in the picture
(1 cyan, 2 yellow, 3 magenta)."""

from __future__ import annotations

from stairbot.control.algorithm.phases import Phase

PHASE_WORDS: dict[Phase, str] = {
    Phase.CAL_CHECK: "squaring up: reading the front sensors",
    Phase.CAL_CLOSE_IN: "squaring up: driving closer",
    Phase.CAL_LIFT: "squaring up: raising the ends clear",
    Phase.CAL_TURN: "squaring up: turning till fronts agree",
    Phase.CAL_TURN_TO: "squaring up: turning to a heading",
    Phase.CAL_PROBE: "squaring up: looking left (a corner?)",
    Phase.CAL_CORNER: "squaring up: turning out of a corner",
    Phase.CAL_AWAY: "squaring up: turning from a side wall",
    Phase.CAL_LOWER: "squaring up: lowering the ends",
    Phase.ASCENT_APPROACH: "driving up to the step",
    Phase.ASCENT_APPROACH_TURNS: "driving the last bit to the step",
    Phase.ASCENT_LIFT_FIRST: "raising segment 1 (front)",
    Phase.ASCENT_LIFT_FIRST_MORE: "raising segment 1 above the step",
    Phase.ASCENT_LOWER_OBSTACLE: "step too high: lowering segment 1",
    Phase.ASCENT_DRIVE_FIRST: "driving segment 1 onto the step",
    Phase.ASCENT_LIFT_SECOND: "raising segment 2 (middle)",
    Phase.ASCENT_DRIVE_SECOND: "driving segment 2 onto the step",
    Phase.ASCENT_LIFT_THIRD: "raising segment 3 (back)",
    Phase.ASCENT_CHECK: "looking for another step",
    Phase.ASCENT_DRIVE_THIRD: "driving segment 3 onto the step",
    Phase.DESCENT_BACK_OFF: "going down: backing to a safe spot",
    Phase.DESCENT_BACK_TO_EDGE: "going down: backing to the edge",
    Phase.DESCENT_LOWER_THIRD: "going down: lowering segment 3",
    Phase.DESCENT_DRIVE_SECOND: "going down: backing segment 2 off",
    Phase.DESCENT_LOWER_SECOND: "going down: lowering segment 2",
    Phase.DESCENT_DRIVE_FIRST: "going down: backing segment 1 off",
    Phase.DESCENT_LOWER_FIRST: "going down: lowering segment 1",
    Phase.DESCENT_FINISH: "backing to the start position",
    Phase.DESCENT_FINISH_FLOOR: "backing to where it started",
    Phase.LANDING_SCAN: "landing: raising segment 3, looking sideways",
    Phase.LANDING_SCAN_LOWER: "landing: lowering segment 3 (which way?)",
    Phase.LANDING_CENTRE: "landing: backing to its middle to turn",
    Phase.LANDING_RETURN: "landing: backing to where it turned",
    Phase.PAUSED: "waiting: a sensor pair disagrees",
    Phase.DONE: "finished",
    Phase.ERROR: "stopped by an error",
}


def phase_words(phase_id: str) -> str:
    """The operator's words for a phase (its value, e.g. "ascent_lift_first");
    "" for none or one this table does not know."""
    try:
        return PHASE_WORDS.get(Phase(phase_id), "")
    except ValueError:
        return ""


def carried_by(phase_id: str) -> tuple[int, ...]:
    """The segments whose wheels stand while ``phase_id`` moves its lifts
    (the phase's ``carried_by``; () when none or unknown)."""
    try:
        return Phase(phase_id).record.carried_by
    except ValueError:
        return ()
