"""Calibration: squaring up to the riser (cases 1, 2, 3A, 3B).

The same phases serve the start of the program (every case), ascent step 1 on
later steps and descent step 1 (case 2 only); the calibration's state
(:class:`~stairbot.control.algorithm.families.Calibration`) says which.
Turning happens on segment 2's wheels with segments 1 and 3 lifted by
NUMBER_OF_VERTICAL_TURNS_FOR_CLEARANCE, slowly, and stops when the smoothed
SFL − SFR reaches zero, so that sensor noise neither stops it early nor
leaves the robot askew.
"""

from __future__ import annotations

import math
from typing import Any

from stairbot.control.algorithm import blind_descent, landing, limits, lost, motion
from stairbot.control.algorithm.families import Calibration
from stairbot.control.algorithm.modes import LANDING_PURPOSES, CalibrationCase, Outcome, Purpose
from stairbot.control.algorithm.moves import lift
from stairbot.control.algorithm.phase import (
    ENDED,
    FAILED,
    FAULT,
    NO_MOTION,
    Exit,
    PhaseDef,
    Step,
    Tick,
    end,
    fail,
    go,
    stay,
    where,
)
from stairbot.control.algorithm.phases import Mode, Phase
from stairbot.control.algorithm.squaring import (
    HEADING_TOLERANCE_RAD,
    MAX_SQUARE_YAW_RAD,
    MAX_SQUARING_TURNS,
    STILL_TICKS,
    askew_rad,
    heading_off_rad,
    mean_diff,
    measured_standing,
    one_riser,
    settled,
    trimmed_mean,
)
from stairbot.control.algorithm.squaring_bias import at_check, beyond, lost_both
from stairbot.control.algorithm.texts import calibration as say
from stairbot.control.algorithm.work import DriveWork, LiftWork, StandingWork
from stairbot.control.tolerances import still_samples, still_tolerance
from stairbot.hardware import MotorId

P = Phase
FLOW = "calibration"

def _after_calibration(t: Tick) -> Step:
    ctx = t.ctx
    if t.cal.purpose is Purpose.DESCENT:
        return go("square_to_descend")
    if ctx.number_of_steps < len(ctx.climb_twist):
        # the heading this step is climbed with: descent 1 comes back to it
        ctx.climb_twist[ctx.number_of_steps] = motion.twist(t.snap)
    landing.after_calibration(t)
    return go("square_to_climb")


# -- check the readings --------------------------------------------------------------
def _check(t: Tick, w: StandingWork) -> Step:
    cfg, ctx, cal = t.cfg, t.ctx, t.cal
    if cal.purpose is Purpose.START and lost.limping(t):
        # squaring up cannot go on one sensor: back to where the program began
        if ctx.start.wheel is None:
            ctx.start.wheel = motion.wheel_position(t.snap)
        return lost.limp_down(t)
    blind = blind_descent.check(t)  # the front pair distrusted: by the odometer
    if blind is not None:
        return blind
    sfr, sfl = motion.pair(t.snap)
    chased = at_check(t, w)  # back from chasing an offset: which sensor changed?
    if chased is not None:
        return chased
    if cal.purpose is Purpose.DESCENT and cal.squaring_turns == 0 \
            and not ctx.descent.turned_back:
        # Descent 1 first turns back to the heading it climbed this step with
        # (by the odometer), so that the way down retraces the way up: squared
        # up within the pair's noise on the way up and again on the way down,
        # the two headings may differ by a few degrees, and over a long flight
        # that put the robot 0.1 m to the side of its start.
        climbed = ctx.climb_twist[t.descent_index]
        if climbed is not None:
            off = heading_off_rad(t, climbed)
            if abs(off) > HEADING_TOLERANCE_RAD:
                cal.turn_to = climbed
                ctx.descent.turned_back = True  # once a step: then the seed's check
                t.say(say.off_climb_heading(t.descent_index, off), off_deg=math.degrees(off))
                return go("off_climb_heading")
    # Standing still, the pair is averaged over STILL_TICKS before it is
    # called equal or not: one noisy reading must not choose the case; and
    # only once the filter has settled (a full window of measurements taken
    # standing here: not the first one or two, nor ones taken while moving).
    if not settled(t, w):
        return stay(NO_MOTION)
    # Checking a squaring turn: as long as it takes to know the difference to
    # within equal_tolerance, as the turn's own check does.
    needed = STILL_TICKS if cal.squaring_turns == 0 else max(
        STILL_TICKS, still_samples(cfg, min(sfr.distance_m, sfl.distance_m)))
    if not measured_standing(t, w, needed):
        return stay(NO_MOTION)
    if cal.squaring_turns > 0:
        return _verify(t, w)
    if motion.far(sfr, cfg) and motion.far(sfl, cfg):
        if cal.purpose is not Purpose.START:
            return fail(say.nothing_ahead_where_riser(where(ctx, P.CAL_CHECK), sfr.distance_m,
                                                      sfl.distance_m))
        cal.case = CalibrationCase.ONE
        t.say(say.case_one(cfg.LENGTH_OF_INFINITY), case="1")
        home = ctx.start.home_wheel
        here = motion.wheel_position(t.snap)
        if home is not None and here - home > motion.WHEEL_DONE:
            # It closed in on a riser it no longer sees (one below the beams
            # it drove up to): descent 7 backs the distance home.
            ctx.start.wheel = here
            t.say(say.CASE_ONE_CLOSED_IN)
            return go("nothing_ahead_closed_in")
        return end(Outcome.STOPPED, say.CASE_ONE_END)
    if cal.purpose is Purpose.START:
        if ctx.start.home_wheel is None:
            ctx.start.home_wheel = motion.wheel_position(t.snap)
            ctx.start.home_twist = motion.twist(t.snap)
        near = _nearer(t)
        if near is not None and near > limits.square_range_m(cfg) + cfg.algorithm.equal_tolerance:
            t.say(say.closing_in(sfr.distance_m, sfl.distance_m, limits.square_range_m(cfg)),
                  SFR=sfr.distance_m, SFL=sfl.distance_m)
            return go("too_far")
    diff = mean_diff(t, w)
    equal = abs(diff) <= still_tolerance(cfg, max(1, len(w.diffs)),
                                         min(sfr.distance_m, sfl.distance_m))
    if equal and cal.purpose is not Purpose.START:
        cal.case = None
        return _after_calibration(t)
    # One beam reading nothing ahead is off the flight's open side (a side
    # wall would be seen): the other sees the riser, and case 2's rule turns
    # the right way.  Only two readings that both see something, too far
    # apart for one riser, are a side wall: taking the open side for one,
    # case 2W would turn away from the riser the other beam sees.
    wall = (not equal and abs(diff) > one_riser(cfg)
            and not motion.far(sfr, cfg) and not motion.far(sfl, cfg))
    cal.case = CalibrationCase.THREE if equal else (
        CalibrationCase.TWO_W if wall else CalibrationCase.TWO)
    cal.case_diff = diff
    if w.standing:  # where the squaring turn began: a chase comes back to it
        cal.checked = (trimmed_mean([r for r, _l in w.standing]),
                       trimmed_mean([l_ for _r, l_ in w.standing]), motion.twist(t.snap))
    t.say(say.case_chosen(where(ctx, P.CAL_CHECK), sfr.distance_m, sfl.distance_m, equal, wall,
                          MAX_SQUARE_YAW_RAD),
          case=cal.case.value, SFR=sfr.distance_m, SFL=sfl.distance_m)
    return go("case_found")


def _verify(t: Tick, w: StandingWork) -> Step:
    """Check a squaring turn standing on all wheels.  The turn ended on the
    readings taken with segments 1 and 3 lifted, their sensors a clearance
    higher: a cone tilted up then sees more of what lies over a low riser,
    and may read equal well askew (17 deg on the reference robot), which
    the standing rule would then stop in the approach.  Not equal here, the robot turns
    by the odometer as far as the difference says (a flat riser, both beams
    on it), and checks again."""
    ctx, cfg, cal = t.ctx, t.cfg, t.cal
    r, l_ = motion.pair(t.snap)
    sfr, sfl = r.distance_m, l_.distance_m
    if cal.beams_lost_rad is not None and motion.far(r, cfg) and motion.far(l_, cfg):
        # lowered, still neither beam meets the riser the turn lost
        return lost_both(t, cal.beams_lost_rad)
    if motion.far(r, cfg) or motion.far(l_, cfg):
        # no figure to square to, nor a riser where it squared up: stop
        return fail(say.nothing_ahead_squared(where(ctx, P.CAL_CHECK), sfr, sfl))
    diff = mean_diff(t, w)
    if abs(diff) <= still_tolerance(cfg, max(1, len(w.diffs)), min(sfr, sfl)):
        t.say(say.square_on_all_wheels(diff, len(w.diffs), sfr, sfl), SFR=sfr, SFL=sfl, diff=diff)
        cal.squaring_turns = 0
        return _squared(t, w)
    if cal.squaring_turns >= MAX_SQUARING_TURNS:
        return fail(say.cannot_square(where(ctx, P.CAL_CHECK), cal.squaring_turns, diff, sfr, sfl))
    # SFL farther than SFR: turned left of square, turn right (and the other way).
    yaw = -askew_rad(cfg, diff)
    yaw = max(-MAX_SQUARE_YAW_RAD, min(MAX_SQUARE_YAW_RAD, yaw))
    target = motion.twist(t.snap) + motion.yaw_turns(cfg, yaw)
    chased = beyond(t, target)
    if chased is not None:
        return chased
    cal.turn_to = target
    cal.squaring_turns += 1
    t.say(say.not_square_on_all_wheels(diff, len(w.diffs), sfr, sfl, yaw),
          SFR=sfr, SFL=sfl, diff=diff)
    return go("not_square")


def _squared(t: Tick, w: StandingWork) -> Step:
    """The calibration is square: the start records where it stands, the
    pair's trimmed means over the ticks the check measured standing still
    (one tick's filtered reading is as noisy as the sensors, and a fault that
    began after the check would count in it whole)."""
    start, cfg = t.ctx.start, t.cfg
    if t.cal.purpose is Purpose.START:
        if w.standing:
            start.reading = (trimmed_mean([r for r, _l in w.standing])
                             + trimmed_mean([l_ for _r, l_ in w.standing])) / 2.0
            start.wheel = motion.wheel_position(t.snap)
            t.say(say.start_position_standing(start.reading, len(w.standing)),
                  start_reading=start.reading)
        elif motion.measurable(t.snap, cfg):
            start.reading = motion.mean_distance(t.snap)
            start.wheel = motion.wheel_position(t.snap)
            t.say(say.start_position(start.reading), start_reading=start.reading)
        if t.mode is Mode.CALIBRATE_ONLY:
            return end(Outcome.COMPLETED, say.CALIBRATE_ONLY_END)
    return _after_calibration(t)


def _nearer(t: Tick) -> float | None:
    """The nearer of SFR and SFL that reads a distance (None: neither)."""
    seen = [r.distance_m for r in motion.pair(t.snap) if r.ok and not motion.far(r, t.cfg)]
    return min(seen, default=None)


CHECK = PhaseDef(
    P.CAL_CHECK, "calibration — check the readings (case 1?)", FLOW, _check, StandingWork,
    family=Calibration,
    on={
        ENDED: Exit(P.DONE, "case 1: both read ≥ LENGTH_OF_INFINITY (nothing ahead); "
                            "calibrate-only: squared up (checked)"),
        "too_far": Exit(P.CAL_CLOSE_IN, "start: the nearer reads farther than square_range_m"),
        "nothing_ahead_closed_in": Exit(P.DESCENT_FINISH, "case 1 after closing in: back to "
                                                          "where the program began"),
        "case_found": Exit(P.CAL_LIFT, "start: case 2 (SFR ≠ SFL), 2W (too far apart for one "
                                       "riser) or case 3 (SFR = SFL); later: SFR ≠ SFL"),
        "off_climb_heading": Exit(P.CAL_LIFT, "descent 1: turned from the heading the step "
                                              "was climbed with"),
        "not_square": Exit(P.CAL_LIFT, "a squaring turn checked and not square: correct it"),
        "chased": Exit(P.CAL_LIFT, "descent 1: the correction would turn further from the "
                                   "climbed heading than square allows: back to it"),
        "square_to_climb": Exit(P.ASCENT_APPROACH, "ascent 1 on a later step: SFR = SFL; or "
                                                   "squared up (checked)"),
        "square_to_descend": Exit(P.DESCENT_BACK_TO_EDGE, "descent 1: SFR = SFL; or squared up "
                                                          "(checked); or turned back to the "
                                                          "climbed heading, the front pair "
                                                          "lost"),
        "limp_home_floor": Exit(P.DESCENT_FINISH, lost.LIMP + ": start, back to where the "
                                                  "program began"),
        FAILED: Exit(P.ERROR, "case 1: sensor error; later: nothing ahead where a riser should "
                              "be; checking a squaring turn: nothing ahead (both beams lost in "
                              "the turn: a sensor may read an offset), or still not square "
                              "after MAX_SQUARING_TURNS turns"),
    })


# -- close in (start) -------------------------------------------------------------------
def _close_in_enter(t: Tick, w: DriveWork) -> None:
    # No further than the first reading allows: its nearer beam to square_range_m.
    near = _nearer(t)
    assert near is not None  # CAL_CHECK closes in only on a reading
    w.target_wheel = w.entry_wheel + t.cfg.wheel_turns(near - limits.square_range_m(t.cfg))


def _close_in(t: Tick, w: DriveWork) -> Step:
    """Drive straight on, not squared up (the standing rule is not armed), until
    the nearer beam reads square_range_m or the first reading's distance is
    driven; then check the readings again, standing still."""
    assert w.target_wheel is not None  # set on entry
    near = _nearer(t)
    remaining = w.target_wheel - motion.wheel_position(t.snap)
    square = limits.square_range_m(t.cfg)
    if remaining <= motion.WHEEL_DONE or (near is not None and near <= square):
        return go("closed_in", say.closed_in(near))
    return stay(motion.drive(t.cfg, 1, remaining))


CLOSE_IN = PhaseDef(
    P.CAL_CLOSE_IN, "calibration — close in to square_range_m", FLOW, _close_in,
    DriveWork, enter=_close_in_enter, family=Calibration,
    on={"closed_in": Exit(P.CAL_CHECK, "the nearer reads square_range_m, or the first "
                                       "reading's distance driven"),
        FAILED: Exit(P.ERROR, FAULT)})


# -- lift segments 1 and 3 for clearance -----------------------------------------------
def _lift_deltas(t: Tick, w: LiftWork) -> dict[MotorId, float]:
    cal, cfg = t.cal, t.cfg
    cal.return_mtf, cal.return_mtb = w.entry_mtf, w.entry_mtb
    up = cfg.NUMBER_OF_VERTICAL_TURNS_FOR_CLEARANCE
    limit = cfg.MAX_OF_VERTICAL_TURNS
    return {MotorId.MTF: min(up, limit - w.entry_mtf), MotorId.MTB: min(up, limit - w.entry_mtb)}


def _lifted(t: Tick, _w: LiftWork) -> Step:
    cal = t.cal
    if cal.squaring_turns == 0:
        # a calibration's first turn; its corrections count towards the same
        # MAX_TURN_YAW_RAD
        cal.turn_origin = t.snap.turns(MotorId.MWR)
    if cal.turn_to is not None:
        return go("to_heading")
    case = cal.case
    return go("case_2" if case is CalibrationCase.TWO
              else "case_2w" if case is CalibrationCase.TWO_W else "case_3")


_lift_enter, _lift_step = lift(_lift_deltas, _lifted)
LIFT = PhaseDef(
    P.CAL_LIFT, "calibration — lift segments 1 and 3 for clearance", FLOW, _lift_step,
    LiftWork, enter=_lift_enter, carried_by=(2,), family=Calibration,
    on={"case_2": Exit(P.CAL_TURN, "lifted; case 2"),
        "case_2w": Exit(P.CAL_AWAY, "lifted; case 2W"),
        "case_3": Exit(P.CAL_PROBE, "lifted; case 3"),
        "to_heading": Exit(P.CAL_TURN_TO, "lifted; a correction of the squaring turn, or "
                                          "descent 1 or 7 turning back to a heading it had"),
        FAILED: Exit(P.ERROR, FAULT)})


# -- lower segments 1 and 3 --------------------------------------------------------------
def _lower_deltas(t: Tick, w: LiftWork) -> dict[MotorId, float]:
    cal = t.cal
    return {MotorId.MTF: cal.return_mtf - w.entry_mtf, MotorId.MTB: cal.return_mtb - w.entry_mtb}


def _lowered(t: Tick, _w: LiftWork) -> Step:
    cal = t.cal
    cal.turn_to = None
    if cal.purpose is Purpose.HOME:
        return go("home")
    if cal.purpose is Purpose.FLOOR:
        return go("floor")
    if cal.purpose is Purpose.EDGE:
        return go("edge")
    if cal.purpose in LANDING_PURPOSES:
        return landing.turned(t)
    # Check standing on all wheels, once the filter has settled there (the
    # check waits for it): a squaring turn (squaring_turns > 0), or descent
    # 1's turn back to the climb's heading (the seed's check).  Segment 1
    # settling onto its wheels pitches the beams down for a moment, and a
    # cone then reads the floor (the reference robot took its start reading there,
    # 0.202 m for 0.327 m, and came home 0.125 m short).
    return go("lowered")


_lower_enter, _lower_step = lift(_lower_deltas, _lowered)
LOWER = PhaseDef(
    P.CAL_LOWER, "calibration — lower segments 1 and 3", FLOW, _lower_step, LiftWork,
    enter=_lower_enter, carried_by=(2,), family=Calibration,
    on={"home": Exit(P.DESCENT_FINISH_FLOOR, "lowered (descent 7, turned back to where the "
                                             "program began)"),
        "floor": Exit(P.DESCENT_FINISH, "lowered (descent 7, turned back to the floor's "
                                        "heading)"),
        "edge": Exit(P.DESCENT_BACK_TO_EDGE, "lowered (continuous descent, turned square to "
                                             "the edge)"),
        "lowered": Exit(P.CAL_CHECK, "lowered: check standing on all wheels"),
        **landing.TURNED,
        FAILED: Exit(P.ERROR, FAULT)})

PHASES: tuple[PhaseDef[Any], ...] = (CHECK, CLOSE_IN, LIFT, LOWER)
"""This module's phases; the turns' are in :mod:`~stairbot.control.algorithm.turns`."""
