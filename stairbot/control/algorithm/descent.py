"""Descent steps 1–7, one step at a time from the top, back to the start.

i is the step being descended (0-based, into tab_length_to_edge); h is
number_of_turns_for_step_height as descent 2 measures it.  Descent 2 lowers
segment 3 (MTB down) until SBR/SBL read BACK_CLEARANCE; descent 4 moves MTF and
MTB by +h (segment 2 goes down); descent 6 moves MTF by −h.  The drives end at
a reading measured against tab_length_to_edge[i]; where that is not
measurable (the top step reads "nothing ahead") they go by the seed's turn
counts.
"""

from __future__ import annotations

import math
from typing import Any

from stairbot.control.algorithm import landing, long_tread, motion
from stairbot.control.algorithm.ascent import narrow
from stairbot.control.algorithm.calibration import HEADING_TOLERANCE_RAD, heading_off_rad
from stairbot.control.algorithm.edge import (
    edge_bound,
    edge_clearance_m,
    floor_tolerance,
    narrow_bound,
    refind,
)
from stairbot.control.algorithm.families import LowerThird
from stairbot.control.algorithm.modes import Outcome, Purpose
from stairbot.control.algorithm.moves import (
    checked_first,
    drive_phase,
    lift,
    lift_phase,
    reading_drive,
    turns_drive,
)
from stairbot.control.algorithm.phase import (
    FAULT,
    PhaseDef,
    Step,
    Tick,
    calibrate,
    end,
    fail,
    go,
    stay,
    where,
)
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.work import (
    DriveWork,
    EdgeWork,
    LiftWork,
    LowerThirdWork,
    RefuseWork,
)
from stairbot.hardware import BACK_SENSORS, MotorId, SensorStatus
from stairbot.inputs.config import RobotConfig

P = Phase
FLOW = "descent"


def _tab(t: Tick) -> float | None:
    return t.ctx.tab_length_to_edge[t.descent_index]


def _tread(t: Tick) -> float | None:
    """The tread ascent 3 measured for the step being descended (None: not
    measured, or not climbed)."""
    i = t.descent_index
    return t.ctx.tread_length[i] if 0 <= i < len(t.ctx.tread_length) else None


def _h(t: Tick) -> float:
    return t.ctx.number_of_turns_for_step_height


def _narrow(t: Tick, index: int | None = None) -> bool:
    """The tread of step ``index`` (default: the one being descended, which
    the robot stands on) is narrow: the robot does not fit on it, and its
    segment 3 hangs in the air over the step below (narrow_steps)."""
    i = t.descent_index if index is None else index
    return not t.ctx.from_top and 0 <= i and narrow(t.cfg, t.ctx.tread_length[i])


# -- descent 1: back off, calibrate, back up to the edge ---------------------------------------
def _backed_off(t: Tick, w: EdgeWork) -> Step:
    if w.edge_stop is not None:
        return fail(w.edge_stop)
    if w.square_yaw is not None:
        return _turn_square(t, w)
    if t.ctx.from_top:
        # squared up to the edge by the back pair instead: the front pair
        # faces risers the robot did not climb, and one too low for its cone
        # reads as nothing ahead, which calibration takes for case 1
        return go(P.DESCENT_BACK_TO_EDGE)
    return calibrate(Purpose.DESCENT)


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
    return _tab(t) if _narrow(t) else None


def _edge_or_tab(t: Tick, w: EdgeWork, refind: bool) -> float | None:
    """The edge watch's bound (:func:`~stairbot.control.algorithm.edge.edge_bound`);
    on a narrow step, the tab read on the way up places the robot (the back
    pair is over the step below, segment 3 in the air), bounded by
    :func:`~stairbot.control.algorithm.edge.narrow_bound`."""
    if not _narrow(t):
        return edge_bound(t, w, refind)
    limit = narrow_bound(t, w)
    if limit is None or w.target_wheel is None:
        return limit
    # a limit, not where the drive ends (backing up to the edge is exact to its bound)
    return max(limit, w.target_wheel)


def _narrow_tab_known(t: Tick, _w: EdgeWork) -> Step | None:
    if _narrow(t) and _tab(t) is None:
        return fail(f"descent 1: tab_length_to_edge[{t.descent_index}] was not measured on "
                    "a narrow step: the robot cannot be placed on a tread it does not fit on")
    return None


def _back_off_turns(t: Tick) -> float:
    """The seed's approach turns; on a narrow step, while the front pair
    cannot read (descent 6 left it nearer the riser than it reads from),
    the tab less the approach's gap, where descent 5 left segment 1's front
    face: on a tread shorter than the robot the seed's turns (0.1 m) take
    segment 2's rear wheels over the edge, and the robot tips back."""
    tab = _tab(t)
    if _narrow(t) and tab is not None:
        return t.cfg.wheel_turns(max(0.0, tab - t.cfg.algorithm.approach_gap))
    return t.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH


_back_off_drive = reading_drive(-1, _back_off_target, _back_off_turns,
                                _backed_off, lambda t, w: _edge_or_tab(t, w, refind=False))
BACK_OFF = PhaseDef(
    P.DESCENT_BACK_OFF, "descent 1 — back off to a safe position", FLOW,
    checked_first(_narrow_tab_known, _back_off_drive[1]), EdgeWork,
    enter=_back_off_enter, watches="front",
    to={P.CAL_CHECK: "turns made, or backed edge_clearance_m past where SBR/SBL saw the "
                     "edge; on a narrow step, reads tab_length_to_edge[i]: calibrate "
                     "(case 2)",
        P.DESCENT_BACK_TO_EDGE: "continuous descent: the same, not calibrating (the back "
                                "pair squares up at the edge)",
        P.CAL_LIFT: "continuous descent: SBR and SBL read the drop more than "
                    "EDGE_SQUARE_RAD apart: lift to turn square to the edge",
        P.ERROR: "one back sensor reads the drop and the other not within "
                 "MAX_EDGE_YAW_RAD; a narrow step's tab_length_to_edge unknown; " + FAULT})


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
    riser, and the robot went on).  Not on a narrow step, whose tab places
    the robot."""
    return t.ctx.from_top or (_tab(t) is None and not _narrow(t))


def unmeasured_search_m(t: Tick) -> float:
    """A climbed step whose tab was not measured: how far backing up to the
    edge looks for it, the tread as ascent 3 measured it (the robot stands
    on it), or LENGTH_OF_INFINITY."""
    tread = _tread(t)
    return tread if tread is not None and math.isfinite(tread) else t.cfg.LENGTH_OF_INFINITY


def _edge_fallback(t: Tick) -> float:
    if t.ctx.from_top:
        return t.cfg.wheel_turns(edge_search_m(t))
    if _edge_by_watch(t):
        return t.cfg.wheel_turns(unmeasured_search_m(t))
    # Descent 1 backed off to SAFE_DISTANCE_IN_FRONT_OF_STEP before calibrating.
    tab = _tab(t) or t.cfg.SAFE_DISTANCE_IN_FRONT_OF_STEP
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
        return fail(f"descent 1: tab_length_to_edge[{t.descent_index}] was not measured, and "
                    f"SBR/SBL saw no edge backing {searched:.2f} m (the tread measured, or "
                    "LENGTH_OF_INFINITY): the edge of the step cannot be found")
    if not ctx.from_top or ctx.descent.edge_wheel is not None:
        return go(P.DESCENT_LOWER_THIRD)
    if ctx.steps_descended == 0:
        return end(Outcome.STOPPED, f"no edge behind: SBR/SBL read the floor for {searched:.2f} m "
                              f"backing from the start (at most LENGTH_OF_INFINITY = "
                              f"{t.cfg.LENGTH_OF_INFINITY} m): not on the top of a flight")
    return end(Outcome.COMPLETED, f"on the floor, or a landing: no edge within {searched:.2f} m "
                            f"behind step {ctx.steps_descended} from the top, the last "
                            "descended")


_to_edge = reading_drive(-1, _tab, _edge_fallback, _at_edge,
                         lambda t, w: _edge_or_tab(t, w, refind=True), exact=True)


def _to_edge_step(t: Tick, w: EdgeWork) -> Step:
    if w.refind_from is None:
        step = _to_edge[1](t, w)
        if w.edge_stop is not None:
            return fail(w.edge_stop)
        if w.square_yaw is not None:
            return _turn_square(t, w)
        if w.refind_from is None:
            return step
        # the watch found the pair past an edge it did not see crossed: this
        # tick's step (which may have ended the backing) is not taken
    return refind(t, w)


def _turn_square(t: Tick, w: EdgeWork) -> Step:
    """Lift segments 1 and 3 and turn on segment 2's wheels by the odometer
    (calibration's turn to a heading), square to the edge; then back up to
    it again, finding the floor first (the pair is past the edge now)."""
    assert w.square_yaw is not None
    t.ctx.descent.edge_squared = True
    return calibrate(Purpose.EDGE, motion.twist(t.snap) + motion.yaw_turns(t.cfg, w.square_yaw),
                     f"turning {math.degrees(w.square_yaw):+.1f}° square to the edge")


BACK_TO_EDGE = PhaseDef(
    P.DESCENT_BACK_TO_EDGE, "descent 1 — back up to the edge", FLOW,
    _to_edge_step, EdgeWork, enter=_to_edge[0], watches="front",
    to={P.DESCENT_LOWER_THIRD: "backed edge_clearance_m past where SBR/SBL crossed the "
                                "edge (driving forward first until they read the floor, "
                                "if they were past it unseen); or, not crossed yet, reads "
                                "tab_length_to_edge[i]; on a narrow step, reads it (no "
                                "edge watch)",
        P.CAL_LIFT: "continuous descent: SBR and SBL read the drop more than "
                    "EDGE_SQUARE_RAD apart: lift to turn square to the edge",
        P.DONE: "continuous descent: no edge within the search (edge_search_m): on the "
                "floor; or, from the start, not on the top of a flight; or the floor not "
                "found again: the tread is shorter than the robot (stopped)",
        P.ERROR: "tab_length_to_edge[i] unknown and no edge seen within the tread; the floor "
                 "not found again; one back "
                 "sensor reads the drop and the other not within MAX_EDGE_YAW_RAD; " + FAULT})


# -- descent 2: lower segment 3 until the back sensors find the step below ------------------------
def _lt(t: Tick) -> LowerThird:
    return t.ctx.family_of(LowerThird)


def _lower_third_enter(t: Tick, w: LowerThirdWork) -> None:
    _lt(t).return_mtb = w.entry_mtb
    w.target_mtb = -t.cfg.MAX_OF_VERTICAL_TURNS


def _over_an_edge(t: Tick, _w: LowerThirdWork) -> Step | None:
    cfg = t.cfg
    reading = motion.mean_distance(t.snap, back=True)
    if reading <= cfg.BACK_CLEARANCE + floor_tolerance(cfg):
        return fail(f"floor not found: SBR/SBL read {reading:.3f} m, at or below BACK_CLEARANCE "
                    f"({cfg.BACK_CLEARANCE} m), before segment 3 was lowered (step "
                    f"{t.descent_index + 1}): segment 3 is not over an edge")
    return None


def _refuse_because(t: Tick, why: str) -> Step:
    """Refuse the drop below (``why`` is said, and kept for the end)."""
    t.say(why)
    _lt(t).refused = why
    return go(P.DESCENT_REFUSE, why)


def lowerable_m(cfg: RobotConfig, mtb: float) -> float:
    """How far segment 3 can go down from MTB's counter ``mtb``: to
    -MAX_OF_VERTICAL_TURNS."""
    return max(0.0, cfg.MAX_OF_VERTICAL_TURNS + mtb) * cfg.motors.lift_travel_per_turn


def _deep_drop(t: Tick, w: LowerThirdWork) -> Step | None:
    """Continuous descent: a drop below the edge deeper than segment 3 can be
    lowered (SBR/SBL read the step below further than that past
    BACK_CLEARANCE, or nothing within their range when the range is beyond
    it) is refused before the lift moves.  (Descending steps it climbed, the
    robot knows each drop is one it lifted.)"""
    cfg = t.cfg
    if not t.ctx.from_top:
        return None
    most = lowerable_m(cfg, w.entry_mtb)
    backs = [t.snap.sensors[s] for s in BACK_SENSORS]
    if all(r.ok for r in backs):
        depth = min(r.distance_m for r in backs) - cfg.BACK_CLEARANCE
        if depth > most + floor_tolerance(cfg):
            return _refuse_because(t, f"the drop below step {t.ctx.steps_descended + 1} from "
                                   f"the top is {depth:.3f} m (SBR/SBL), deeper than segment "
                                   f"3 can be lowered ({most:.3f} m): refused")
    elif all(r.status is SensorStatus.OUT_OF_RANGE and r.distance_m > cfg.BACK_CLEARANCE
             for r in backs):
        reach = cfg.sensors.range(back=True)[1] - cfg.BACK_CLEARANCE
        if reach > most:
            return _refuse_because(t, f"nothing within SBR/SBL's range below step "
                                   f"{t.ctx.steps_descended + 1} from the top: the drop is "
                                   f"deeper than {reach:.3f} m, more than segment 3 can be "
                                   f"lowered ({most:.3f} m): refused")
    return None


def _floor_not_found(t: Tick, reading: float) -> Step:
    """MTB's stroke ends before SBR/SBL read BACK_CLEARANCE: an error
    descending a step climbed (a sensor reads wrong), refused in a
    continuous descent (the drop is deeper than the lift)."""
    cfg, ctx = t.cfg, t.ctx
    if ctx.from_top:
        return _refuse_because(t, f"floor not found below step {ctx.steps_descended + 1} "
                               f"from the top within MTB's stroke (-MAX_OF_VERTICAL_TURNS): "
                               f"SBR/SBL read {reading:.3f} m: refused")
    return fail(f"floor not found when descending step {t.descent_index + 1}: MTB reached "
                f"-MAX_OF_VERTICAL_TURNS ({-cfg.MAX_OF_VERTICAL_TURNS:.0f}) and SBR/SBL "
                f"still read {reading:.3f} m")


def _lower_third(t: Tick, w: LowerThirdWork) -> Step:
    ctx, cfg = t.ctx, t.cfg
    reading = motion.mean_distance(t.snap, back=True)
    to_go = reading - cfg.BACK_CLEARANCE
    if not w.finishing and to_go <= floor_tolerance(cfg):
        # Within the noise of BACK_CLEARANCE: the rest the reading says, by
        # turns, and no further (an unbiased finish, never a push on the floor).
        w.finishing = True
        w.target_mtb = t.snap.turns(MotorId.MTB) - cfg.lift_turns(max(0.0, to_go))
        if w.target_mtb < -cfg.MAX_OF_VERTICAL_TURNS - motion.LIFT_DONE:
            # the floor lies past the end of the stroke (the lift would never
            # get there: a drop 5 mm deeper than the stroke waited out the
            # phase's timeout)
            return _floor_not_found(t, reading)
    if w.finishing:
        assert w.target_mtb is not None
        finish = motion.lift_to(cfg, t.snap, MotorId.MTB, w.target_mtb)
        if finish is not None:
            return stay({MotorId.MTB: finish})
        ctx.number_of_turns_for_step_height = _lt(t).return_mtb - t.snap.turns(MotorId.MTB)
        ctx.third_in_air = False  # on the step below
        ctx.descent.narrow_edge_wheel = None  # the next edge's, if narrow, is watched for
        t.say(f"segment 3 on the step below: number_of_turns_for_step_height = "
              f"{ctx.number_of_turns_for_step_height:.2f} ({where(ctx, P.DESCENT_LOWER_THIRD)})",
              number_of_turns_for_step_height=ctx.number_of_turns_for_step_height)
        return go(P.DESCENT_DRIVE_SECOND)
    assert w.target_mtb is not None
    limit = motion.lift_to(cfg, t.snap, MotorId.MTB, w.target_mtb)
    if limit is None:
        return _floor_not_found(t, reading)
    backs = [t.snap.sensors[s] for s in BACK_SENSORS]
    if all(r.ok for r in backs):
        speed = motion.approach(cfg.motors.lift_speed, cfg.lift_turns(to_go),
                                motion.LIFT_SLOW_ZONE, cfg.algorithm.tick)
        return stay({MotorId.MTB: -min(speed, abs(limit))})
    return stay({MotorId.MTB: limit})  # out of range far: nothing below yet, keep lowering


LOWER_THIRD = PhaseDef(
    P.DESCENT_LOWER_THIRD, "descent 2 — lower segment 3", FLOW,
    checked_first(lambda t, w: _over_an_edge(t, w) or _deep_drop(t, w), _lower_third),
    LowerThirdWork,
    enter=_lower_third_enter, watches="back", carried_by=(1, 2), family=LowerThird,
    to={P.DESCENT_DRIVE_SECOND: "SBR/SBL read BACK_CLEARANCE: "
                                "number_of_turns_for_step_height stored",
        P.DESCENT_REFUSE: "continuous descent: SBR/SBL read a drop deeper than segment 3 "
                          "can be lowered, or nothing in range; or the floor not found "
                          "within MAX_OF_VERTICAL_TURNS",
        P.ERROR: "reads ≤ BACK_CLEARANCE at the start, or floor not found "
                 "within MAX_OF_VERTICAL_TURNS; " + FAULT})


# -- descent 2, refused: segment 3 up again, and the robot back onto the step -------------------
RETREAT_MARGIN_M = 0.03
"""Refused, the robot drives forward this much more than it backed past where
the back pair crossed the edge: segment 3 wholly on the step again."""


def _refuse_enter(t: Tick, w: RefuseWork) -> None:
    w.target_mtb = _lt(t).return_mtb  # where descent 2 began lowering


def _refuse(t: Tick, w: RefuseWork) -> Step:
    cfg = t.cfg
    speeds = motion.lifts_to(cfg, t.snap, w.lift_targets())
    if speeds is not None:
        return stay(speeds)
    here = motion.wheel_position(t.snap)
    if w.target_wheel is None:
        w.target_wheel = here + cfg.wheel_turns(edge_clearance_m(cfg) + RETREAT_MARGIN_M)
    remaining = w.target_wheel - here
    if remaining <= motion.WHEEL_DONE:
        why = _lt(t).refused or f"refused the drop below step {t.ctx.steps_descended + 1}"
        return end(Outcome.STOPPED, f"{why}; segment 3 raised again, the robot back on the step")
    return stay(motion.drive(cfg, 1, remaining))


REFUSE = PhaseDef(
    P.DESCENT_REFUSE, "descent 2 — refused: raise segment 3, drive back onto the step", FLOW,
    _refuse, RefuseWork, enter=_refuse_enter, carried_by=(1, 2), family=LowerThird,
    to={P.DONE: "segment 3 raised to where descent 2 began, and driven forward "
                "edge_clearance_m and RETREAT_MARGIN_M: the robot on the step (stopped)",
        P.ERROR: FAULT})


# -- descent 3-6: segment by segment off the step ----------------------------------------------
FAR_TAB_M = 0.5
"""Descent 3 and 5 drive by the seed's turn counts, as where the tab is not
measurable, when the step's tab_length_to_edge is longer than this: the
wall ahead is a landing's (a tread of 0.63 m or more), which the front pair
reads from up to LENGTH_OF_INFINITY, where its noise is largest, while the
back pair has just placed the edge behind (descent 1) exactly.  A
VL53L1X pair's sigma at 1 m is about 8 mm: a drive to a tab that far ends
that much short, lowers segment 1's wheel onto the edge, and tips the
robot."""


TAB_SIGMA_MAX_M = 0.0065
"""Descent 3 and 5 drive by turns, too, where the front pair's stated sigma
at the tab is more than this: the tab is one reading, and where descent 3
ends is as far off as it.  The threshold sits between the sigmas the
drives to a tab handle (up to 6 mm: the ir robot's Sharp pair at 0.25 m,
the longest tabs of the envelope; a VL53L1X pair at 0.5 m, 5.5 mm) and
those that end descent 3 short enough for segment 2, lowered onto the
edge, to pitch the robot to the tilt stop (the Sharp pair at 0.34 m,
7.8 mm)."""


def _tab_to_drive(t: Tick) -> float | None:
    """The tab descent 3 and 5 drive to, or None: by turns (FAR_TAB_M; or a
    tread past FAR_TREAD_M, which the ascent drove onto by turns: its tab,
    0.35 to 0.45 m on treads of 0.5 to 0.6 m, read with the cone over a
    riser lower than min_rise_for, jumps 22-27 mm as the robot backs, and
    descent 3 or 5 would end short enough to pitch segment 2 to the tilt
    stop)."""
    tab = _tab(t)
    if tab is None or tab > FAR_TAB_M or long_tread.far(_tread(t)) \
            or t.cfg.sensors.sigma(False, tab) > TAB_SIGMA_MAX_M:
        return None
    return tab


def _second_target(t: Tick) -> float | None:
    tab = _tab_to_drive(t)
    return None if tab is None else t.cfg.LENGTH_OF_SECOND_MODULE + tab


def _first_target(t: Tick) -> float | None:
    tab = _tab_to_drive(t)
    if tab is None:
        return None
    return t.cfg.LENGTH_OF_FIRST_MODULE + t.cfg.LENGTH_OF_SECOND_MODULE + tab


DRIVE_SECOND = drive_phase(
    P.DESCENT_DRIVE_SECOND, "descent 3 — drive segment 2 off the step", FLOW, -1,
    _second_target, lambda t: t.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_SECOND_MODULE,
    P.DESCENT_LOWER_SECOND, "reads LENGTH_OF_SECOND_MODULE + tab_length_to_edge[i] "
    "(or turns made)", work=DriveWork)

LOWER_SECOND = lift_phase(
    P.DESCENT_LOWER_SECOND, "descent 4 — lower segment 2", FLOW,
    lambda t, _w: {MotorId.MTF: _h(t), MotorId.MTB: _h(t)}, P.DESCENT_DRIVE_FIRST, (1, 3))


def _first_bound(t: Tick, w: EdgeWork) -> float | None:
    """Descent 5 onto a narrow tread: watch its edge go by
    (:func:`~stairbot.control.algorithm.edge.narrow_bound`); the drive's own target
    is not bounded."""
    if _narrow(t, t.descent_index - 1):
        narrow_bound(t, w)
    return None


def _driven_first(t: Tick, _w: EdgeWork) -> Step:
    # on a narrow tread below, segment 3 has backed off its edge: in the air over the next
    t.ctx.third_in_air = _narrow(t, t.descent_index - 1)
    return go(P.DESCENT_LOWER_FIRST)


DRIVE_FIRST = drive_phase(
    P.DESCENT_DRIVE_FIRST, "descent 5 — drive segment 1 off the step", FLOW, -1,
    _first_target, lambda t: t.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE,
    P.DESCENT_LOWER_FIRST, "reads LENGTH_OF_FIRST_MODULE + LENGTH_OF_SECOND_MODULE + "
    "tab_length_to_edge[i] (or turns made); onto a narrow tread, segment 3 is in the air now",
    _driven_first, _first_bound, work=EdgeWork)


def _lowered_first(t: Tick, _w: LiftWork) -> Step:
    ctx = t.ctx
    ctx.steps_descended += 1
    if ctx.from_top:
        t.say(f"step {ctx.steps_descended} from the top descended",
              steps_descended=ctx.steps_descended)
        return go(P.DESCENT_BACK_OFF)
    t.say(f"step {ctx.number_of_steps - ctx.steps_descended + 1} descended "
          f"({ctx.steps_descended} of {ctx.number_of_steps})", steps_descended=ctx.steps_descended)
    if landing.returns_here(t):
        return go(P.LANDING_RETURN)
    if ctx.steps_descended < ctx.number_of_steps:
        return go(P.DESCENT_BACK_OFF)
    ctx.descent.turned_back = False  # descent 7 turns back to the floor's heading once
    return go(P.DESCENT_FINISH)


_lower1 = lift(lambda t, _w: {MotorId.MTF: -_h(t)}, _lowered_first)
LOWER_FIRST = PhaseDef(
    P.DESCENT_LOWER_FIRST, "descent 6 — lower segment 1", FLOW, _lower1[1], LiftWork,
    enter=_lower1[0],
    carried_by=(2, 3),
    to={P.DESCENT_BACK_OFF: "turns made; steps remain (a continuous descent: always)",
        P.LANDING_RETURN: "turns made; down the first step of the flight after a landing's "
                          "turn: back to where it turned",
        P.DESCENT_FINISH: "turns made; all number_of_steps descended", P.ERROR: FAULT})


# -- descent 7: back to the start ----------------------------------------------------------------
def _on_the_floor_all_along(t: Tick) -> bool:
    """No step was climbed: the wheels drove only on the floor, and their
    odometer knows the way back better than a reading of stairs it refused
    (a cone may see over low risers there)."""
    return t.ctx.number_of_steps == 0 and t.ctx.start.wheel is not None


def _finish_turns(t: Tick) -> float:
    """How far descent 7 backs while the front pair cannot measure: by the
    odometer if no step was climbed; else from the riser (approach_gap
    away) to the start reading -- not the seed's
    NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH, within which a pair that reads
    only from 10 cm (a Sharp) may not yet measure, which would stop the
    robot 0.4 m short."""
    start, cfg = t.ctx.start, t.cfg
    if _on_the_floor_all_along(t):
        assert start.wheel is not None
        return max(0.0, motion.wheel_position(t.snap) - start.wheel)
    if start.reading is None:
        return cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH
    return cfg.wheel_turns(max(0.0, start.reading - cfg.algorithm.approach_gap))


def _closed_in_turns(t: Tick) -> float:
    """How far the first calibration closed in before it squared up (turns)."""
    start = t.ctx.start
    if start.wheel is None or start.home_wheel is None:
        return 0.0
    return max(0.0, start.wheel - start.home_wheel)


def _at_start_position(t: Tick, _w: DriveWork) -> Step:
    """At the start position (where the first calibration squared up).  If it
    closed in first, the way home retraces it: turn back to the heading the
    program began with (segments 1 and 3 lifted, as calibration turns), then
    back the distance."""
    home_twist = t.ctx.start.home_twist
    if _closed_in_turns(t) <= motion.WHEEL_DONE:
        return end(Outcome.COMPLETED, "back at the start position")
    if home_twist is None or abs(heading_off_rad(t, home_twist)) <= HEADING_TOLERANCE_RAD:
        return go(P.DESCENT_FINISH_FLOOR)
    return calibrate(Purpose.HOME, home_twist)


def _floor_heading(t: Tick, _w: DriveWork) -> Step | None:
    """Before backing to the start position: turn back (once) to the heading
    the robot crossed the floor with, where the first calibration left it
    (climb_twist[0]), if the odometer says it is further off than
    HEADING_TOLERANCE_RAD.  Descent 1 squared up to the first riser again, and
    a start squared up far away within a noisy pair's tolerance may differ
    from that by degrees: backing the whole way to the start on the squarer
    heading would put the robot centimetres to the side of it."""
    ctx = t.ctx
    floor = ctx.climb_twist[0]
    if ctx.descent.turned_back or floor is None:
        return None
    ctx.descent.turned_back = True
    off = heading_off_rad(t, floor)
    if abs(off) <= HEADING_TOLERANCE_RAD:
        return None
    t.say(f"descent 7: turned {math.degrees(off):+.2f}° from the heading it crossed the floor "
          "with (by the odometer); turning back to it", off_deg=math.degrees(off))
    return calibrate(Purpose.FLOOR, floor)


_finish = reading_drive(-1, lambda t: None if _on_the_floor_all_along(t) else t.ctx.start.reading,
                        _finish_turns, _at_start_position)
FINISH = PhaseDef(
    P.DESCENT_FINISH, "descent 7 — finish: back off to the start position", FLOW,
    checked_first(_floor_heading, _finish[1]), DriveWork, enter=_finish[0], watches="front",
    to={P.DONE: "reads the start reading (or turns made; with no step climbed: back by the "
                "odometer to the start position)",
        P.CAL_LIFT: "turned from the heading it crossed the floor with: lift to turn back to "
                    "it; or, the first calibration closed in, turned from the heading the "
                    "program began with: lift to turn back",
        P.DESCENT_FINISH_FLOOR: "the first calibration closed in; turned within "
                                "HEADING_TOLERANCE_RAD of the heading it began with",
        P.ERROR: FAULT})


_floor = turns_drive(-1, _closed_in_turns,
                     lambda _t, _w: end(Outcome.COMPLETED, "back where the program began"))
FINISH_FLOOR = PhaseDef(
    P.DESCENT_FINISH_FLOOR, "descent 7 — finish: back the distance calibration closed in",
    FLOW, _floor[1], DriveWork, enter=_floor[0],
    to={P.DONE: "turns made: where the program began", P.ERROR: FAULT})

PHASES: tuple[PhaseDef[Any], ...] = (
    BACK_OFF, BACK_TO_EDGE, LOWER_THIRD, REFUSE, DRIVE_SECOND, LOWER_SECOND, DRIVE_FIRST,
    LOWER_FIRST, FINISH, FINISH_FLOOR,
)
