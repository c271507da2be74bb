"""Ascent steps 2 and 4–9 (step 1 is calibration:
:mod:`stairbot.control.algorithm.calibration`; step 3 lifting segment 1:
:mod:`stairbot.control.algorithm.lift_first`).

h below is number_of_turns_for_step_height, as ascent 3 measured it.
Ascent 5 moves MTF and MTB by −h together (segment 2 rises), ascent
7 moves MTB by +h (segment 3 rises).  The drives of steps 4, 6 and 9 end at a
reading when the distance is measurable and by turns when it is not.
"""

from __future__ import annotations

import statistics
from typing import Any

from stairbot.control.algorithm import (
    blind,
    blocked,
    long_tread,
    lost,
    motion,
    sight,
    split_top,
    undo_first,
)
from stairbot.control.algorithm.families import LiftFirst
from stairbot.control.algorithm.lift_first import (
    LIFT_FIRST,
    LIFT_FIRST_MORE,
    LOWER_OBSTACLE,
    narrow,
)
from stairbot.control.algorithm.modes import AscentEnd, Purpose
from stairbot.control.algorithm.moves import (
    KEY_TICKS,
    RISER_KEYS,
    drive_phase,
    lift,
    lift_phase,
)
from stairbot.control.algorithm.phase import (
    FAILED,
    FAULT,
    NO_MOTION,
    Exit,
    PhaseDef,
    Step,
    Tick,
    calibrate,
    fail,
    go,
    stay,
)
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.texts import ascent as say
from stairbot.control.algorithm.work import (
    ApproachTurnsWork,
    ApproachWork,
    DriveWork,
    LiftWork,
    WaitWork,
)
from stairbot.hardware import MotorId, SensorStatus

P = Phase
FLOW = "ascent"

LIMP_DOWN = {
    "limp_home": Exit(P.DESCENT_BACK_OFF, lost.LIMP + ": down the steps climbed"),
    "limp_home_floor": Exit(P.DESCENT_FINISH, lost.LIMP + ": none climbed, back to the start"),
}

# -- ascent 2: approach --------------------------------------------------------------------
RISER_LOST_WAIT_S = 0.5
"""Ascent 2: a beam that reads "nothing ahead" stops the approach; the riser
is lost (an error) only if it still does after this long standing still."""


def _approach(t: Tick, w: ApproachWork) -> Step:
    cfg, ctx = t.cfg, t.ctx
    if lost.limping(t):
        return lost.limp_down(t)
    if w.blocked_since is not None:
        return blocked.step(t, w)
    sfr, sfl = motion.pair(t.snap)
    if motion.far(sfr, cfg) or motion.far(sfl, cfg):
        # A riser does not vanish from in front of a robot on the floor: stand
        # and measure again before calling it lost (two outliers among a slow
        # sensor's three last measurements pass its median).
        if w.still_since is None:
            w.still_since = t.snap.time_s
        if t.snap.time_s - w.still_since < RISER_LOST_WAIT_S:
            return stay(NO_MOTION)
        return fail(say.riser_lost(ctx.number_of_steps, sfr.distance_m, sfl.distance_m,
                                   RISER_LOST_WAIT_S))
    w.still_since = None
    reading = _riser_ahead(t, w)
    if blocked.went_away(t, w):
        return stay(NO_MOTION)
    safe = cfg.SAFE_DISTANCE_IN_FRONT_OF_STEP
    if reading <= safe:
        return go("at_safe_distance")
    remaining = cfg.wheel_turns(reading - safe) + cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH
    return stay(motion.drive(cfg, 1, remaining))


def _riser_ahead(t: Tick, w: ApproachWork) -> float:
    """How far the riser is: the median over the last RISER_KEYS ticks of
    the mean reading plus the odometer (``ctx.riser_wheel``), less the
    odometer now; the reading itself until KEY_TICKS ticks have measured it.
    Many ticks, not one: two outliers among an HC-SR04's last three
    measurements pass its median, one tick's reading can be centimetres
    short, and an approach that takes it for its start stops that far from
    the riser, where lifting segment 3 tips the robot nose up."""
    cfg, ctx = t.cfg, t.ctx
    reading = motion.mean_distance(t.snap)
    here = motion.wheel_position(t.snap)
    if motion.measurable(t.snap, cfg):
        keys = w.riser_keys
        keys.append(here + cfg.wheel_turns(reading))
        del keys[:-RISER_KEYS]
        if len(keys) >= KEY_TICKS:
            ctx.riser_wheel = statistics.median(keys)
            return (ctx.riser_wheel - here) * cfg.wheel_circumference
    return reading


BLOCKED = "the riser placed went away (blocked.BLOCKED_M): a step below the beams"

APPROACH = PhaseDef(
    P.ASCENT_APPROACH, "ascent 2 — approach to SAFE_DISTANCE_IN_FRONT_OF_STEP", FLOW, _approach,
    ApproachWork, watches="front",
    on={"at_safe_distance": Exit(P.ASCENT_APPROACH_TURNS, "reads "
                                                         "SAFE_DISTANCE_IN_FRONT_OF_STEP"),
        "blocked_on_the_floor": Exit(P.DESCENT_FINISH, BLOCKED + "; none climbed"),
        "blocked_steps_climbed": Exit(P.DESCENT_BACK_OFF, BLOCKED + "; number_of_steps > 0"),
        "blocked_after_turn": Exit(P.LANDING_RETURN, BLOCKED + "; the first step after a "
                                                             "landing's turn"),
        **LIMP_DOWN,
        FAILED: Exit(P.ERROR, "riser lost (nothing ahead, standing RISER_LOST_WAIT_S); "
                              + FAULT)})


def _approach_turns_enter(t: Tick, w: ApproachTurnsWork) -> None:
    # From SAFE_DISTANCE_IN_FRONT_OF_STEP on, NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH
    # more.  A robot that starts nearer (after ascent 9) drives only the rest.
    cfg = t.cfg
    w.start_reading = motion.mean_distance(t.snap)
    reckoned = _reckoned_riser(t, w)
    if reckoned is not None:
        w.start_reading = reckoned
    nearer = cfg.SAFE_DISTANCE_IN_FRONT_OF_STEP - w.start_reading
    w.target_wheel = w.entry_wheel + cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH \
        - cfg.wheel_turns(nearer)


def _reckoned_riser(t: Tick, w: ApproachTurnsWork) -> float | None:
    """How far the riser is by dead reckoning from where the approach's
    readings (or ascent 9's) put it, ``ctx.riser_wheel`` (the median of many
    ticks, where the reading now is one); when a front sensor reads "too
    near", only if nearer than its clamp (a bound); else None."""
    cfg = t.cfg
    riser = t.ctx.riser_wheel
    if riser is None:
        return None
    reckoned = (riser - w.entry_wheel) * cfg.wheel_circumference
    if reckoned < 0.0:
        return None
    if any(r.status is SensorStatus.OUT_OF_RANGE and not motion.far(r, cfg)
           for r in motion.pair(t.snap)) and reckoned >= motion.mean_distance(t.snap):
        return None
    return reckoned


def _approach_turns(t: Tick, w: ApproachTurnsWork) -> Step:
    if lost.limping(t):
        return lost.limp_down(t)
    assert w.target_wheel is not None and w.start_reading is not None  # set on entry
    here = motion.wheel_position(t.snap)
    remaining = w.target_wheel - here
    if remaining <= motion.WHEEL_DONE:
        # The sensors read "too near" from here on: the gap is dead reckoned.
        driven = (here - w.entry_wheel) * t.cfg.wheel_circumference
        gap = max(0.0, w.start_reading - driven)
        t.say(say.at_riser(gap), riser_gap=gap)
        return go("at_riser", begin=LiftFirst(riser_gap=gap))
    return stay(motion.drive(t.cfg, 1, remaining))


APPROACH_TURNS = PhaseDef(
    P.ASCENT_APPROACH_TURNS, "ascent 2 — approach: NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH more",
    FLOW, _approach_turns, ApproachTurnsWork, enter=_approach_turns_enter, watches="front",
    on={"at_riser": Exit(P.ASCENT_LIFT_FIRST, "turns made"), **LIMP_DOWN,
        FAILED: Exit(P.ERROR, FAULT)})


# -- ascent 4-7: segment by segment onto the step -------------------------------------------
def _reading_length(t: Tick, ahead_m: float, segment_2_lifted: bool = False) -> float | None:
    """length_of_next_step for a drive onto the step that starts with the
    next riser length - ``ahead_m`` away to end at a reading
    (long_tread.near_length), or None (by turns): also when the front pair,
    at the pitch the robot stands at, meets the tread before that riser
    (:mod:`~stairbot.control.algorithm.sight`): it would read the tread,
    which rides along with the robot, and end the drive short."""
    length = long_tread.near_length(t)
    if length is None:
        return None
    cfg = t.cfg
    pitch = sight.pitch_now(cfg, t.snap, segment_2_lifted)
    riser = length - ahead_m
    if sight.riser_in_sight(cfg, riser, pitch):
        return length
    t.say(say.riser_out_of_sight(t.ctx.number_of_steps, riser, pitch,
                                 sight.floor_sight_m(cfg, pitch)),
          riser_m=riser, pitch_deg=pitch, by_turns=True)
    return None


def _first_target(t: Tick) -> float | None:
    length = _reading_length(t, 0.0)
    return None if length is None else length - t.cfg.LENGTH_OF_FIRST_MODULE


def _second_target(t: Tick) -> float | None:
    cfg = t.cfg
    length = _reading_length(t, cfg.LENGTH_OF_FIRST_MODULE, segment_2_lifted=True)
    if length is None:
        return None
    return length - cfg.LENGTH_OF_FIRST_MODULE - cfg.LENGTH_OF_SECOND_MODULE


def _third_target(t: Tick) -> float | None:
    """length_of_next_step − LENGTH_OF_A_ROBOT, or, on a narrow step (which
    the robot does not fit on), no nearer the next riser than a tread of
    min_tread_m would leave it (SAFE_LENGTH and the approach's gap): segment
    3 stays in the air over the step below.  None (by turns) past
    FAR_TREAD_M, or out of the front pair's sight, as for ascent 4 and 6."""
    cfg = t.cfg
    length = _reading_length(t, cfg.LENGTH_OF_FIRST_MODULE + cfg.LENGTH_OF_SECOND_MODULE)
    if length is None:
        return None
    return max(length - cfg.LENGTH_OF_A_ROBOT, cfg.SAFE_LENGTH + cfg.algorithm.approach_gap)


def _h(t: Tick) -> float:
    return t.ctx.number_of_turns_for_step_height


def _driven_first(t: Tick, _w: DriveWork) -> Step:
    # segment 3, in the air over the step below if that is narrow, has rolled on with the
    # robot onto the tread behind the riser just climbed: it carries again
    t.ctx.third_in_air = False
    return go("reached")


DRIVE_FIRST = undo_first.with_undo(drive_phase(
    P.ASCENT_DRIVE_FIRST, "ascent 4 — drive segment 1 onto the step", FLOW, 1, _first_target,
    lambda t: t.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE, P.ASCENT_LIFT_SECOND,
    "reads length_of_next_step − LENGTH_OF_FIRST_MODULE (or turns made); from a narrow "
    "step, segment 3 on its tread again", _driven_first, work=DriveWork))

LIFT_SECOND = lift_phase(
    P.ASCENT_LIFT_SECOND, "ascent 5 — lift segment 2", FLOW,
    lambda t, _w: {MotorId.MTF: -_h(t), MotorId.MTB: -_h(t)}, P.ASCENT_DRIVE_SECOND, (1, 3))

def _driven_second(t: Tick, w: DriveWork) -> Step:
    # by turns, segment 2 ends 10-15 mm further on than by a reading (ascent 5
    # slid the robot forward, which the wheels do not count), and so does the
    # tab ascent 7 reads there: descent 3 and 5 go by turns off this step
    i = t.ctx.number_of_steps
    if i < len(t.ctx.second_by_turns):
        t.ctx.second_by_turns[i] = w.target_reading is None
    return go("reached")


DRIVE_SECOND = drive_phase(
    P.ASCENT_DRIVE_SECOND, "ascent 6 — drive segment 2 onto the step", FLOW, 1, _second_target,
    lambda t: t.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_SECOND_MODULE, P.ASCENT_LIFT_THIRD,
    "reads length_of_next_step − LENGTH_OF_FIRST_MODULE − LENGTH_OF_SECOND_MODULE "
    "(or turns made)", _driven_second, work=DriveWork)


def _lifted_third(t: Tick, _w: LiftWork) -> Step:
    ctx, cfg = t.ctx, t.cfg
    i = ctx.number_of_steps
    if motion.measurable(t.snap, cfg):
        tab = ctx.tab_length_to_edge[i] = motion.mean_distance(t.snap)
        t.say(say.tab_length(i, tab), index=i, tab_length_to_edge=tab)
    else:
        ctx.tab_length_to_edge[i] = None
        t.say(say.tab_not_measurable(i, blind.front_unusable(ctx)), index=i,
              tab_length_to_edge=None)
    ctx.number_of_steps += 1
    t.say(say.number_of_steps(ctx.number_of_steps), number_of_steps=ctx.number_of_steps)
    return go("turns_made")


LIFT_THIRD_MAX_PITCH_DEG = 3.0
"""Ascent 7: segment 2's most nose-up pitch while segment 3 rises.  Lifting
segment 3 only levels a robot that ascent 5 left nose down (-4.5 degrees on
the shipped robots, to about 0 at the lift's end); one whose segment 2 did
not reach the step (its rear axle behind the nosing) pitches on past level
as segment 3 rises, the nosing a fulcrum, until it tips back off the edge
(the ir robot on a 0.48 m tread: -4.5 to +10.5 degrees, then the fall
faster than the tilt stop at 15 degrees could hold it; stopped at +3 degrees
it stood, segment 3 still on the tread below: docs/envelope.md, "Reach").
Healthy climbs end ascent 7 at +0.1 to +0.3 degrees."""


def _lift_third(t: Tick, w: LiftWork) -> Step:
    imu, cfg = t.snap.imu, t.cfg
    if cfg.safety.imu and imu is not None and imu.pitch_deg > LIFT_THIRD_MAX_PITCH_DEG:
        # the supervisor's tilt watch has ended the run on a pitch that is
        # not a number, and on a stale IMU the controller holds
        return fail(say.tipping_back(t.ctx.number_of_steps, imu.pitch_deg,
                                     LIFT_THIRD_MAX_PITCH_DEG))
    return _lift3[1](t, w)


_lift3 = lift(lambda t, _w: {MotorId.MTB: _h(t)}, _lifted_third)
LIFT_THIRD = PhaseDef(
    P.ASCENT_LIFT_THIRD, "ascent 7 — lift segment 3", FLOW, _lift_third, LiftWork,
    enter=_lift3[0], watches="front", carried_by=(1, 2),
    on={"turns_made": Exit(P.ASCENT_CHECK, "turns made; tab_length_to_edge[i] stored, "
                                           "number_of_steps + 1"),
        FAILED: Exit(P.ERROR, f"{say.TIPPING_BACK_EDGE}; {FAULT}")})


# -- ascent 8-9: the top, or the next step ------------------------------------------------------
def _check(t: Tick, w: WaitWork) -> Step:
    ctx, cfg = t.ctx, t.cfg
    if lost.limping(t):
        return go("limp_home")
    sfr, sfl = motion.pair(t.snap)
    if motion.far(sfr, cfg) and motion.far(sfl, cfg):
        ctx.ascent_end = AscentEnd.TOP_REACHED
        t.say(say.top_reached(ctx.number_of_steps), ascent_end="top_reached")
        return go("top_reached")
    tab = split_top.tab_again(t, w)
    if tab is not None:
        return tab
    if ctx.number_of_steps >= cfg.algorithm.max_steps:
        ctx.ascent_end = AscentEnd.STEP_LIMIT
        t.say(say.step_limit(cfg.algorithm.max_steps), ascent_end="step_limit")
        return go("step_limit")
    return go("next_step")


CHECK = PhaseDef(
    P.ASCENT_CHECK, "ascent 8 — check the distance (top?)", FLOW, _check, WaitWork,
    watches="front",
    on={"top_reached": Exit(P.DESCENT_LOWER_THIRD, "reads ≥ LENGTH_OF_INFINITY (top reached); "
                                                   "or, no tab, one beam nothing ahead and the "
                                                   "other no riser (split_top)"),
        "step_limit": Exit(P.DESCENT_LOWER_THIRD, "number_of_steps = max_steps"),
        "limp_home": Exit(P.DESCENT_LOWER_THIRD, lost.LIMP + ": the step finished, down it"),
        "next_step": Exit(P.ASCENT_DRIVE_THIRD, "otherwise"),
        FAILED: Exit(P.ERROR, FAULT)})


def _driven_third(t: Tick, w: DriveWork) -> Step:
    t.ctx.riser_wheel = None
    t.ctx.third_in_air = narrow(t.cfg, t.ctx.tread_length[t.ctx.number_of_steps - 1])
    if w.target_reading is not None and not w.reading_lost and w.target_wheel is not None:
        # where the last readings put the riser: ascent 2 starts from it if
        # the sensors cannot read that near
        t.ctx.riser_wheel = w.target_wheel + t.cfg.wheel_turns(w.target_reading)
    return calibrate("reached", Purpose.ASCENT)


DRIVE_THIRD = drive_phase(
    P.ASCENT_DRIVE_THIRD, "ascent 9 — drive segment 3 onto the step", FLOW, 1, _third_target,
    lambda t: t.cfg.wheel_turns(t.cfg.LENGTH_OF_THIRD_MODULE), P.CAL_CHECK,
    "reads length_of_next_step − LENGTH_OF_A_ROBOT, on a narrow step SAFE_LENGTH + "
    "approach_gap (or turns made): next step, ascent 1", _driven_third, work=DriveWork)

PHASES: tuple[PhaseDef[Any], ...] = (
    APPROACH, APPROACH_TURNS, LIFT_FIRST, LIFT_FIRST_MORE, LOWER_OBSTACLE, DRIVE_FIRST,
    LIFT_SECOND, DRIVE_SECOND, LIFT_THIRD, CHECK, DRIVE_THIRD,
)
