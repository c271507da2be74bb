"""Descent 1: back off to a safe position, calibrate (case 2), back up to the
edge -- the back pair's edge watch bounding both backings
(:mod:`~stairbot.control.algorithm.edge`).  In a continuous descent the back
pair squares the robot up to the edge instead of calibration.
"""

from __future__ import annotations

import math

from stairbot.control.algorithm import blind, motion
from stairbot.control.algorithm.edge import (
    edge_bound,
    edge_stopped,
    narrow_bound,
    refind,
)
from stairbot.control.algorithm.edge_measure import slow_backing
from stairbot.control.algorithm.modes import Outcome, Purpose
from stairbot.control.algorithm.moves import (
    checked_first,
    reading_drive,
)
from stairbot.control.algorithm.phase import (
    ENDED,
    FAILED,
    FAULT,
    Exit,
    PhaseDef,
    Step,
    Tick,
    calibrate,
    end,
    fail,
    go,
    stay,
)
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.step_down import narrow_here, step_tab, step_tread
from stairbot.control.algorithm.texts import descent as say
from stairbot.control.algorithm.work import (
    EdgeWork,
)

P = Phase
FLOW = "descent"

ASKEW_TO_EDGE: dict[str, Exit] = {
    "askew_to_edge": Exit(P.CAL_LIFT, "continuous descent: SBR and SBL read the drop more than "
                                      "EDGE_SQUARE_RAD apart: lift to turn square to the edge")}
"""The outcome of :func:`_turn_square` (segments 1 and 3 lift, to turn
square to the edge), in both backings' records."""


# -- descent 1: back off, calibrate, back up to the edge ---------------------------------------
def _backed_off(t: Tick, w: EdgeWork) -> Step:
    if w.edge_stop is not None:
        return edge_stopped(w)
    if w.square_yaw is not None:
        return _turn_square(t, w)
    if t.ctx.from_top:
        # squared up to the edge by the back pair instead: the front pair
        # faces risers the robot did not climb, and one too low for its cone
        # reads as nothing ahead, which calibration takes for case 1
        return go("backed_off_from_top")
    return calibrate("backed_off", Purpose.DESCENT)


def _back_off_enter(t: Tick, w: EdgeWork) -> None:
    t.ctx.descent.edge_wheel = None  # a new step: its edge not seen yet, nor turned back
    t.ctx.descent.turned_back = t.ctx.descent.edge_squared = False
    _back_off_drive[0](t, w)


def _back_off_target(t: Tick) -> float | None:
    """None (the seed's turns), or, on a narrow step, tab_length_to_edge: the
    robot does not fit on the tread, and backing off the seed's approach
    turns would take segment 2's wheels over the edge.  Its segment 3 hangs
    over the step below already; where segment 2's rear wheels stand on the
    edge is where ascent 7 read the tab."""
    return step_tab(t) if narrow_here(t) else None


def _edge_or_tab(t: Tick, w: EdgeWork, refind: bool) -> float | None:
    """The edge watch's bound (:func:`~stairbot.control.algorithm.edge.edge_bound`);
    on a narrow step, the tab read on the way up places the robot (the back
    pair is over the step below, segment 3 in the air), bounded by
    :func:`~stairbot.control.algorithm.edge.narrow_bound`."""
    if not narrow_here(t):
        return edge_bound(t, w, refind)
    limit = narrow_bound(t, w)
    if limit is None or w.target_wheel is None:
        return limit
    # a limit, not where the drive ends (backing up to the edge is exact to its bound)
    return max(limit, w.target_wheel)


def _narrow_tab_known(t: Tick, _w: EdgeWork) -> Step | None:
    if narrow_here(t) and step_tab(t) is None:
        return fail(say.narrow_tab_unknown(t.descent_index))
    return None


def _back_off_turns(t: Tick) -> float:
    """The seed's approach turns; on a narrow step, while the front pair
    cannot read (descent 6 left it nearer the riser than it reads from),
    the tab less the approach's gap, where descent 5 left segment 1's front
    face: on a tread shorter than the robot the seed's turns (0.1 m) take
    segment 2's rear wheels over the edge, and the robot tips back."""
    tab = step_tab(t)
    if narrow_here(t) and tab is not None:
        return t.cfg.wheel_turns(max(0.0, tab - t.cfg.algorithm.approach_gap))
    return t.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH


_back_off_drive = reading_drive(-1, _back_off_target, _back_off_turns,
                                _backed_off, lambda t, w: _edge_or_tab(t, w, refind=False))
BACK_OFF = PhaseDef(
    P.DESCENT_BACK_OFF, "descent 1 — back off to a safe position", FLOW,
    checked_first(_narrow_tab_known, _back_off_drive[1]), EdgeWork,
    enter=_back_off_enter, watches="front",
    on={"backed_off": Exit(P.CAL_CHECK, "turns made, or backed edge_clearance_m past where "
                                        "SBR/SBL saw the edge; on a narrow step, reads "
                                        "tab_length_to_edge[i]: calibrate (case 2)"),
        "backed_off_from_top": Exit(P.DESCENT_BACK_TO_EDGE, "continuous descent: the same, "
                                                            "not calibrating (the back pair "
                                                            "squares up at the edge)"),
        **ASKEW_TO_EDGE,
        FAILED: Exit(P.ERROR, "one back sensor reads the drop and the other not within "
                              "MAX_EDGE_YAW_RAD; a narrow step's tab_length_to_edge unknown; "
                              + FAULT)})


def edge_search_m(t: Tick) -> float:
    """Continuous descent: how far backing up to the edge looks for it before
    taking what the robot stands on for the floor.  From the start on the top,
    LENGTH_OF_INFINITY (the operator set the robot down near the edge); on a
    step below, LENGTH_OF_A_ROBOT + SAFE_LENGTH past where the back-off and
    calibration left it, so that a tread up to about twice the shortest the
    robot enters, and the back-off's length, is a step, and a longer one
    the floor (or a landing)."""
    cfg = t.cfg
    if t.ctx.steps_descended == 0:
        return cfg.LENGTH_OF_INFINITY
    return cfg.LENGTH_OF_A_ROBOT + cfg.SAFE_LENGTH


def _edge_by_watch(t: Tick) -> bool:
    """Backing up to the edge goes by the back pair's edge watch alone: in a
    continuous descent, and on a climbed step whose tab_length_to_edge was
    not measured (the riser ahead about LENGTH_OF_INFINITY away, which one
    beam reached and the other not: ascent 7 read nothing, ascent 8 read a
    riser, and the robot went on); and with the front pair distrusted
    (:mod:`~stairbot.control.algorithm.blind`), which reads no tab.  Not on a
    narrow step, whose tab places the robot."""
    return t.ctx.from_top or ((step_tab(t) is None or blind.front_unusable(t.ctx))
                              and not narrow_here(t))


def unmeasured_search_m(t: Tick) -> float:
    """A climbed step whose tab was not measured: how far backing up to the
    edge looks for it, the tread as ascent 3 measured it (the robot stands
    on it), or LENGTH_OF_INFINITY."""
    tread = step_tread(t)
    return tread if tread is not None and math.isfinite(tread) else t.cfg.LENGTH_OF_INFINITY


def _edge_fallback(t: Tick) -> float:
    if t.ctx.from_top:
        return t.cfg.wheel_turns(edge_search_m(t))
    if _edge_by_watch(t):
        return t.cfg.wheel_turns(unmeasured_search_m(t))
    # Descent 1 backed off to SAFE_DISTANCE_IN_FRONT_OF_STEP before calibrating.
    tab = step_tab(t) or t.cfg.SAFE_DISTANCE_IN_FRONT_OF_STEP
    return t.cfg.wheel_turns(max(0.0, tab - t.cfg.SAFE_DISTANCE_IN_FRONT_OF_STEP))


# Once the back pair has crossed the edge, the backing ends edge_clearance_m
# past it, wherever tab_length_to_edge would stop it: the tab, read on the
# way up where segment 3 was lifted over the edge, can leave segment 3's
# front wheels on the edge's corner, and lowered there segment 3 stays up
# while the lift pitches the robot.
def _at_edge(t: Tick, w: EdgeWork) -> Step:
    """Backed up to the edge.  In a continuous descent, backing the whole
    search without seeing an edge is the floor.  (Its tab_length_to_edge stay
    unknown, and descent 3 and 5 go by the seed's turn counts: the front pair
    looks back up at risers the robot did not climb, and a cone sees over a
    low one as the robot backs away from it, so its reading jumps to the
    riser beyond; a drive by it would end at once, and segment 1, lowered on
    the edge, would pitch the robot nose up.)"""
    ctx = t.ctx
    searched = (w.entry_wheel - motion.wheel_position(t.snap)) * t.cfg.wheel_circumference
    if not ctx.from_top and ctx.descent.edge_wheel is None and _edge_by_watch(t):
        return fail(say.edge_not_found(t.descent_index, searched))
    if not ctx.from_top or ctx.descent.edge_wheel is not None:
        return go("at_edge")
    if ctx.steps_descended == 0:
        return end(Outcome.STOPPED, say.not_on_top(searched, t.cfg.LENGTH_OF_INFINITY))
    return end(Outcome.COMPLETED, say.on_the_floor(searched, ctx.steps_descended))


_to_edge = reading_drive(-1, step_tab, _edge_fallback, _at_edge,
                         lambda t, w: _edge_or_tab(t, w, refind=True), exact=True)


def _to_edge_step(t: Tick, w: EdgeWork) -> Step:
    if _refinding(w):
        return refind(t, w)
    step = _to_edge[1](t, w)
    if w.edge_stop is not None:
        return edge_stopped(w)
    if w.square_yaw is not None:
        return _turn_square(t, w)
    if _refinding(w):
        # the watch found the pair past an edge it did not see crossed: this
        # tick's step (which may have ended the backing) is not taken
        return refind(t, w)
    return _slowed(t, w, step)


def _refinding(w: EdgeWork) -> bool:
    """Whether backing up to the edge is finding the floor again
    (``w.refind_from`` set).  A function, not a test of ``w.refind_from``
    in :func:`_to_edge_step`: the step's edge watch may set it, and mypy
    keeps an attribute narrowed across a call, so a second test there would
    still take it for None (and compiled by mypyc, reading it as None raises
    TypeError once it holds a float)."""
    return w.refind_from is not None


def _slowed(t: Tick, w: EdgeWork, step: Step) -> Step:
    """After finding the floor again, the backing at
    :func:`~stairbot.control.algorithm.edge_measure.slow_backing`."""
    if not w.edge_slow or step.happened is not None:
        return step
    slow = slow_backing(t.cfg)
    return stay({m: v * slow for m, v in step.speeds.items()})


def _turn_square(t: Tick, w: EdgeWork) -> Step:
    """Lift segments 1 and 3 and turn on segment 2's wheels by the odometer
    (calibration's turn to a heading), square to the edge; then back up to
    it again, finding the floor first (the pair is past the edge now)."""
    assert w.square_yaw is not None
    t.ctx.descent.edge_squared = True
    return calibrate("askew_to_edge", Purpose.EDGE,
                     motion.twist(t.snap) + motion.yaw_turns(t.cfg, w.square_yaw),
                     say.turning_square_to_edge(w.square_yaw))


BACK_TO_EDGE = PhaseDef(
    P.DESCENT_BACK_TO_EDGE, "descent 1 — back up to the edge", FLOW,
    _to_edge_step, EdgeWork, enter=_to_edge[0], watches="front",
    on={"at_edge": Exit(P.DESCENT_LOWER_THIRD, "backed edge_clearance_m past where SBR/SBL "
                                               "crossed the edge (driving forward first until "
                                               "they read the floor, if they were past it "
                                               "unseen); or, not crossed yet, reads "
                                               "tab_length_to_edge[i]; on a narrow step, reads "
                                               "it (no edge watch)"),
        **ASKEW_TO_EDGE,
        ENDED: Exit(P.DONE, "continuous descent: no edge within the search (edge_search_m): on "
                            "the floor; or, from the start, not on the top of a flight; or the "
                            "floor not found again: the tread is shorter than the robot "
                            "(stopped)"),
        FAILED: Exit(P.ERROR, "tab_length_to_edge[i] unknown and no edge seen within the "
                              "tread; the floor not found again; one back sensor reads the "
                              "drop and the other not within MAX_EDGE_YAW_RAD; " + FAULT)})
