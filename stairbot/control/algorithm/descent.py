"""Descent steps 2–6, one step at a time from the top (descent 1 is
:mod:`~stairbot.control.algorithm.back_off`, descent 7
:mod:`~stairbot.control.algorithm.homing`).

i is the step being descended (0-based, into tab_length_to_edge); h is
number_of_turns_for_step_height as descent 2 measures it.  Descent 2 lowers
segment 3 (MTB down) until SBR/SBL read BACK_CLEARANCE (or, reading it a
little long, segment 3 is found standing: :mod:`~stairbot.control.algorithm.touchdown`);
descent 4 moves MTF and
MTB by +h (segment 2 goes down); descent 6 moves MTF by −h.  The drives end at
a reading measured against tab_length_to_edge[i]; where that is not
measurable (the top step reads "nothing ahead") they go by the seed's turn
counts.
"""

from __future__ import annotations

from typing import Any

from stairbot.control.algorithm import back_apart, landing, long_tread, motion
from stairbot.control.algorithm.back_off import BACK_OFF, BACK_TO_EDGE
from stairbot.control.algorithm.edge import narrow_bound
from stairbot.control.algorithm.edge_measure import (
    edge_clearance_m,
    edge_lag_s,
    floor_tolerance,
)
from stairbot.control.algorithm.families import LowerThird
from stairbot.control.algorithm.homing import FINISH, FINISH_FLOOR
from stairbot.control.algorithm.modes import Outcome
from stairbot.control.algorithm.moves import (
    checked_first,
    drive_phase,
    lift,
    lift_phase,
)
from stairbot.control.algorithm.phase import (
    ENDED,
    FAILED,
    FAULT,
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
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.step_down import height, narrow_here, step_tab, step_tread
from stairbot.control.algorithm.texts import back_pair as say_touch
from stairbot.control.algorithm.texts import descent as say
from stairbot.control.algorithm.touchdown import stood as stood_on_step
from stairbot.control.algorithm.work import (
    DriveWork,
    EdgeWork,
    LiftWork,
    LowerThirdWork,
    RefuseWork,
)
from stairbot.control.timeline import keep_since, value_at
from stairbot.hardware import BACK_SENSORS, MotorId, SensorStatus
from stairbot.inputs.config import RobotConfig

P = Phase
FLOW = "descent"


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
        return fail(say.not_over_an_edge(reading, cfg.BACK_CLEARANCE, t.descent_index))
    return None


def _refuse_because(t: Tick, why: str) -> Step:
    """Refuse the drop below (``why`` is said, and kept for the end)."""
    t.say(why)
    _lt(t).refused = why
    return go("refused", why)


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
            return _refuse_because(t, say.drop_too_deep(t.ctx.steps_descended, depth, most))
    elif all(r.status is SensorStatus.OUT_OF_RANGE and r.distance_m > cfg.BACK_CLEARANCE
             for r in backs):
        reach = cfg.sensors.range(back=True)[1] - cfg.BACK_CLEARANCE
        if reach > most:
            return _refuse_because(t, say.nothing_in_range_below(t.ctx.steps_descended, reach,
                                                                 most))
    return None


def _floor_not_found(t: Tick, reading: float) -> Step:
    """MTB's stroke ends before SBR/SBL read BACK_CLEARANCE: an error
    descending a step climbed (a sensor reads wrong), refused in a
    continuous descent (the drop is deeper than the lift)."""
    cfg, ctx = t.cfg, t.ctx
    if ctx.from_top:
        return _refuse_because(t, say.floor_beyond_stroke(ctx.steps_descended, reading))
    return fail(say.floor_not_found(t.descent_index, cfg.MAX_OF_VERTICAL_TURNS, reading))


def lowered_unseen_m(t: Tick, w: LowerThirdWork) -> float:
    """How far MTB has lowered segment 3 since the measurements the back
    pair's filtered reading stands for were taken (:func:`edge_lag_s` ago:
    the sensor's latency, then the median's majority of the window): the
    reading is that much long.  Keeps ``w.mtb_recent`` back to then.  An
    HC-SR04 pair's reading lags 0.175 s, 3.5 mm at the lift's full speed,
    more than :func:`floor_tolerance`: uncounted, the lift meets the floor
    near full speed and the finish pushes on by the lag; the push pitches
    segment 2 nose down and raises segment 3's back, its sensors read
    longer, and the reading may never come within the tolerance."""
    now, mtb = t.snap.time_s, t.snap.turns(MotorId.MTB)
    recent = w.mtb_recent
    recent.append((now, mtb))
    then = now - edge_lag_s(t.cfg)
    keep_since(recent, then)
    return max(0.0, value_at(recent, then) - mtb) * t.cfg.motors.lift_travel_per_turn


def _lower_third(t: Tick, w: LowerThirdWork) -> Step:
    ctx, cfg = t.ctx, t.cfg
    reading = back_apart.reading(t.snap, w)  # the mean; the longer one, the pair apart
    to_go = reading - cfg.BACK_CLEARANCE - (0.0 if w.finishing else lowered_unseen_m(t, w))
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
    if not w.finishing:
        stood = stood_on_step(cfg, t.snap, w)
        if stood is not None:  # the pair reads the step below long: segment 3 stands on it
            w.finishing, w.target_mtb = True, stood[0]
            r, left = motion.pair(t.snap, back=True)
            t.say(say_touch.stood_by_touch(r.distance_m, left.distance_m, cfg.BACK_CLEARANCE,
                                           stood[1]))
    if w.finishing:
        assert w.target_mtb is not None
        finish = motion.lift_to(cfg, t.snap, MotorId.MTB, w.target_mtb)
        if finish is not None:
            return stay({MotorId.MTB: finish})
        ctx.number_of_turns_for_step_height = _lt(t).return_mtb - t.snap.turns(MotorId.MTB)
        ctx.third_in_air = False  # on the step below
        ctx.descent.narrow_edge_wheel = None  # the next edge's, if narrow, is watched for
        t.say(say.on_step_below(ctx.number_of_turns_for_step_height,
                                where(ctx, P.DESCENT_LOWER_THIRD)),
              number_of_turns_for_step_height=ctx.number_of_turns_for_step_height)
        return go("on_step_below")
    assert w.target_mtb is not None
    limit = motion.lift_to(cfg, t.snap, MotorId.MTB, w.target_mtb)
    if limit is None:
        return _floor_not_found(t, reading)
    backs = [t.snap.sensors[s] for s in BACK_SENSORS]
    if all(r.ok for r in backs):
        speed = motion.approach(cfg.motors.lift_speed, cfg.lift_turns(to_go),
                                motion.LIFT_BRAKE_ZONE, cfg.algorithm.tick)
        return stay({MotorId.MTB: -min(speed, abs(limit))})
    return stay({MotorId.MTB: limit})  # out of range far: nothing below yet, keep lowering


LOWER_THIRD = PhaseDef(
    P.DESCENT_LOWER_THIRD, "descent 2 — lower segment 3", FLOW,
    checked_first(lambda t, w: _over_an_edge(t, w) or _deep_drop(t, w), _lower_third),
    LowerThirdWork,
    enter=_lower_third_enter, watches="back", carried_by=(1, 2), family=LowerThird,
    on={"on_step_below": Exit(P.DESCENT_DRIVE_SECOND, "SBR/SBL read BACK_CLEARANCE: "
                                                      "number_of_turns_for_step_height stored"),
        "refused": Exit(P.DESCENT_REFUSE, "continuous descent: SBR/SBL read a drop deeper than "
                                          "segment 3 can be lowered, or nothing in range; or "
                                          "the floor not found within MAX_OF_VERTICAL_TURNS"),
        FAILED: Exit(P.ERROR, "reads ≤ BACK_CLEARANCE at the start, or floor not found "
                              "within MAX_OF_VERTICAL_TURNS; " + FAULT)})


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
        why = _lt(t).refused or say.refused_drop(t.ctx.steps_descended)
        return end(Outcome.STOPPED, say.back_on_the_step(why))
    return stay(motion.drive(cfg, 1, remaining))


REFUSE = PhaseDef(
    P.DESCENT_REFUSE, "descent 2 — refused: raise segment 3, drive back onto the step", FLOW,
    _refuse, RefuseWork, enter=_refuse_enter, carried_by=(1, 2), family=LowerThird,
    on={ENDED: Exit(P.DONE, "segment 3 raised to where descent 2 began, and driven forward "
                            "edge_clearance_m and RETREAT_MARGIN_M: the robot on the step "
                            "(stopped)"),
        FAILED: Exit(P.ERROR, FAULT)})


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
    """The tab descent 3 and 5 drive to, or None: by turns (FAR_TAB_M; a
    step whose ascent 6 went by turns, ``second_by_turns``: its tab was read
    with segment 2 10-15 mm further on than a reading drive leaves it, and
    descent 5, placing segment 1 there, left its front wheel on the nosing
    (a nose-down pitch-rate stop lowering it, ir robot, treads 0.36-0.42 m);
    or a tread past FAR_TREAD_M, which the ascent drove onto by turns: its tab,
    0.35 to 0.45 m on treads of 0.5 to 0.6 m, read with the cone over a
    riser lower than min_rise_for, jumps 22-27 mm as the robot backs, and
    descent 3 or 5 would end short enough to pitch segment 2 to the tilt
    stop)."""
    tab = step_tab(t)
    i = t.descent_index
    if 0 <= i < len(t.ctx.second_by_turns) and t.ctx.second_by_turns[i]:
        return None
    if tab is None or tab > FAR_TAB_M or long_tread.far(step_tread(t)) \
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
    lambda t, _w: {MotorId.MTF: height(t), MotorId.MTB: height(t)}, P.DESCENT_DRIVE_FIRST, (1, 3))


def _first_bound(t: Tick, w: EdgeWork) -> float | None:
    """Descent 5 onto a narrow tread: watch its edge go by
    (:func:`~stairbot.control.algorithm.edge.narrow_bound`); the drive's own target
    is not bounded."""
    if narrow_here(t, t.descent_index - 1):
        narrow_bound(t, w)
    return None


def _driven_first(t: Tick, _w: EdgeWork) -> Step:
    # on a narrow tread below, segment 3 has backed off its edge: in the air over the next
    t.ctx.third_in_air = narrow_here(t, t.descent_index - 1)
    return go("reached")


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
        t.say(say.descended_from_top(ctx.steps_descended), steps_descended=ctx.steps_descended)
        return go("steps_remain")
    t.say(say.step_descended(ctx.number_of_steps, ctx.steps_descended),
          steps_descended=ctx.steps_descended)
    if landing.returns_here(t):
        return go("back_to_turn")
    if ctx.steps_descended < ctx.number_of_steps:
        return go("steps_remain")
    ctx.descent.turned_back = False  # descent 7 turns back to the floor's heading once
    return go("all_descended")


_lower1 = lift(lambda t, _w: {MotorId.MTF: -height(t)}, _lowered_first)
LOWER_FIRST = PhaseDef(
    P.DESCENT_LOWER_FIRST, "descent 6 — lower segment 1", FLOW, _lower1[1], LiftWork,
    enter=_lower1[0],
    carried_by=(2, 3),
    on={"steps_remain": Exit(P.DESCENT_BACK_OFF, "turns made; steps remain (a continuous "
                                                 "descent: always)"),
        "back_to_turn": Exit(P.LANDING_RETURN, "turns made; down the first step of the flight "
                                               "after a landing's turn: back to where it "
                                               "turned"),
        "all_descended": Exit(P.DESCENT_FINISH, "turns made; all number_of_steps descended"),
        FAILED: Exit(P.ERROR, FAULT)})


PHASES: tuple[PhaseDef[Any], ...] = (
    BACK_OFF, BACK_TO_EDGE, LOWER_THIRD, REFUSE, DRIVE_SECOND, LOWER_SECOND, DRIVE_FIRST,
    LOWER_FIRST, FINISH, FINISH_FLOOR,
)
"""Descent 1 to 7 (descent 1: :mod:`~stairbot.control.algorithm.back_off`; 7:
:mod:`~stairbot.control.algorithm.homing`)."""
