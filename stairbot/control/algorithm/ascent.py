"""Ascent steps 2–9 (step 1 is calibration: :mod:`stairbot.control.algorithm.calibration`).

h below is number_of_turns_for_step_height.  Ascent 3 lifts segment 1 until
the front sensors see over the step, then number_of_vertical_turns more; h is
the total.  Ascent 5 moves MTF and MTB by −h together (segment 2 rises), ascent
7 moves MTB by +h (segment 3 rises).  The drives of steps 4, 6 and 9 end at a
reading when the distance is measurable and by turns when it is not.
"""

from __future__ import annotations

import math
import statistics
from typing import Any

from stairbot.control.algorithm import landing, limits, long_tread, motion
from stairbot.control.algorithm.families import LiftFirst
from stairbot.control.algorithm.modes import AscentEnd, Purpose
from stairbot.control.algorithm.moves import (
    KEY_TICKS,
    drive_phase,
    lift,
    lift_phase,
)
from stairbot.control.algorithm.phase import (
    FAULT,
    NO_MOTION,
    PhaseDef,
    Step,
    Tick,
    calibrate,
    fail,
    go,
    stay,
)
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.work import (
    ApproachTurnsWork,
    ApproachWork,
    DriveWork,
    LiftWork,
    SightWork,
    WaitWork,
)
from stairbot.hardware import MotorId, SensorStatus
from stairbot.inputs.config import RobotConfig

P = Phase
FLOW = "ascent"

SIGHT_JUMP_M = 0.05
"""Ascent 3: the front sensors see over the riser when both read at least this
much past it (or nothing ahead).  No tread is this short, and it is ten
times the sensors' noise: a noisy reading of the riser never passes for it."""


# -- ascent 2: approach --------------------------------------------------------------------
RISER_LOST_WAIT_S = 0.5
"""Ascent 2: a beam that reads "nothing ahead" stops the approach; the riser
is lost (an error) only if it still does after this long standing still."""


def _approach(t: Tick, w: ApproachWork) -> Step:
    cfg, ctx = t.cfg, t.ctx
    sfr, sfl = motion.pair(t.snap)
    if motion.far(sfr, cfg) or motion.far(sfl, cfg):
        # A riser does not vanish from in front of a robot on the floor: stand
        # and measure again before calling it lost (two outliers among a slow
        # sensor's three last measurements pass its median).
        if w.still_since is None:
            w.still_since = t.snap.time_s
        if t.snap.time_s - w.still_since < RISER_LOST_WAIT_S:
            return stay(NO_MOTION)
        return fail(f"riser lost during the approach (step {ctx.number_of_steps + 1}): "
                    f"SFR {sfr.distance_m:.3f} m, SFL {sfl.distance_m:.3f} m, nothing ahead "
                    f"for {RISER_LOST_WAIT_S:g} s")
    w.still_since = None
    reading = _riser_ahead(t, w)
    safe = cfg.SAFE_DISTANCE_IN_FRONT_OF_STEP
    if reading <= safe:
        return go(P.ASCENT_APPROACH_TURNS)
    remaining = cfg.wheel_turns(reading - safe) + cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH
    return stay(motion.drive(cfg, 1, remaining))


RISER_KEYS = 15
"""Ascent 2 places the riser by the median of this many ticks' readings
(plus the odometer), once it has KEY_TICKS of them."""


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


APPROACH = PhaseDef(
    P.ASCENT_APPROACH, "ascent 2 — approach to SAFE_DISTANCE_IN_FRONT_OF_STEP", FLOW, _approach,
    ApproachWork, watches="front",
    to={P.ASCENT_APPROACH_TURNS: "reads SAFE_DISTANCE_IN_FRONT_OF_STEP",
        P.ERROR: "riser lost (nothing ahead, standing RISER_LOST_WAIT_S); " + FAULT})


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
    assert w.target_wheel is not None and w.start_reading is not None  # set on entry
    here = motion.wheel_position(t.snap)
    remaining = w.target_wheel - here
    if remaining <= motion.WHEEL_DONE:
        # The sensors read "too near" from here on: the gap is dead reckoned.
        driven = (here - w.entry_wheel) * t.cfg.wheel_circumference
        gap = max(0.0, w.start_reading - driven)
        t.say(f"at the riser: {gap:.3f} m from it", riser_gap=gap)
        return go(P.ASCENT_LIFT_FIRST, begin=LiftFirst(riser_gap=gap))
    return stay(motion.drive(t.cfg, 1, remaining))


APPROACH_TURNS = PhaseDef(
    P.ASCENT_APPROACH_TURNS, "ascent 2 — approach: NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH more",
    FLOW, _approach_turns, ApproachTurnsWork, enter=_approach_turns_enter, watches="front",
    to={P.ASCENT_LIFT_FIRST: "turns made", P.ERROR: FAULT})


# -- ascent 3: lift segment 1 -------------------------------------------------------------
def _lf(t: Tick) -> LiftFirst:
    return t.ctx.family_of(LiftFirst)


def _lift_first_enter(t: Tick, w: LiftWork) -> None:
    ctx, cfg = t.ctx, t.cfg
    _lf(t).return_mtf = w.entry_mtf
    w.target_mtf = w.entry_mtf + cfg.MAX_OF_VERTICAL_TURNS - ctx.number_of_vertical_turns


def _gap(t: Tick) -> float:
    gap = _lf(t).riser_gap
    return t.cfg.algorithm.approach_gap if gap is None else gap


def tread_seen(t: Tick) -> float | None:
    """The tread past the riser, once both front sensors see over it: the
    nearer reading less the gap to the riser; +inf for nothing ahead; None
    while either still sees the riser."""
    gap, cfg = _gap(t), t.cfg
    readings = motion.pair(t.snap)
    if not all(motion.far(r, cfg) or (r.ok and r.distance_m >= gap + SIGHT_JUMP_M)
               for r in readings):
        return None
    near = [r.distance_m for r in readings if not motion.far(r, cfg)]
    return min(near) - gap if near else float("inf")


def _lift_first(t: Tick, w: LiftWork) -> Step:
    ctx, cfg = t.ctx, t.cfg
    if tread_seen(t) is not None:
        sfr, sfl = (r.distance_m for r in motion.pair(t.snap))
        lifted = t.snap.turns(MotorId.MTF) - _lf(t).return_mtf
        rise = lifted * cfg.motors.lift_travel_per_turn + cfg.sensors.front_height
        t.say(f"segment 1 sees over step {ctx.number_of_steps + 1} after {lifted:.1f} MTF turns "
              f"(rise about {rise:.3f} m): SFR/SFL read {sfr:.3f}/{sfl:.3f} m", rise=rise)
        if rise >= limits.min_step_rise_m(cfg):
            return go(P.ASCENT_LIFT_FIRST_MORE)
        ctx.ascent_end = AscentEnd.OBSTACLE
        t.say(f"step {ctx.number_of_steps + 1} is too low to climb: rise about {rise:.3f} m < "
              f"{limits.min_step_rise_m(cfg):.3f} m (lifting on, the sensors could see past "
              "the next riser); the ascent ends (obstacle)", ascent_end="obstacle")
        return go(P.ASCENT_LOWER_OBSTACLE, "rise lower than the robot measures")
    assert w.target_mtf is not None
    speed = motion.lift_to(cfg, t.snap, MotorId.MTF, w.target_mtf)
    if speed is None:
        ctx.ascent_end = AscentEnd.OBSTACLE
        _lf(t).wall_ahead = True
        allowed = cfg.MAX_OF_VERTICAL_TURNS - ctx.number_of_vertical_turns
        t.say(f"step {ctx.number_of_steps + 1} too high: the front sensors did not see over "
              f"it within {allowed:.1f} MTF turns; the ascent ends (obstacle)",
              ascent_end="obstacle")
        return go(P.ASCENT_LOWER_OBSTACLE)
    return stay({MotorId.MTF: speed})


LIFT_FIRST = PhaseDef(
    P.ASCENT_LIFT_FIRST, "ascent 3 — lift segment 1", FLOW, _lift_first, LiftWork,
    enter=_lift_first_enter, carried_by=(2, 3), family=LiftFirst,
    to={P.ASCENT_LIFT_FIRST_MORE: "sees over the riser (reads ≥ gap + SIGHT_JUMP_M)",
        P.ASCENT_LOWER_OBSTACLE: "MAX_OF_VERTICAL_TURNS − number_of_vertical_turns made: "
                                 "step too high; or sees over a rise < min_step_rise_m",
        P.ERROR: FAULT})


def narrow(cfg: RobotConfig, tread: float | None) -> bool:
    """A tread the robot does not fit on: shorter than LENGTH_OF_A_ROBOT +
    SAFE_LENGTH (climbed only with ``[algorithm] narrow_steps``: min_tread_m)."""
    return tread is not None and tread < cfg.LENGTH_OF_A_ROBOT + cfg.SAFE_LENGTH


def _lifted_first(t: Tick, w: SightWork) -> Step:
    ctx, cfg = t.ctx, t.cfg
    need = limits.min_tread_m(cfg)
    # Measured over the second half of the lift, clear of the edge: at the
    # first sight over it the beam still grazes the step's own tread and
    # reads short.
    tread = _tread_measured(t, w)
    ahead = "nothing ahead" if tread is None or tread == float("inf") \
        else f"tread {tread:.3f} m"
    t.say(f"step {ctx.number_of_steps + 1}: {ahead} (the reading less {_gap(t):.3f} m to the "
          "riser)", tread=None if tread is None or tread == float("inf") else tread)
    if tread is not None and tread < need:
        ctx.ascent_end = AscentEnd.OBSTACLE
        t.say(f"the tread of step {ctx.number_of_steps + 1} is too short: {tread:.3f} m < "
              f"min_tread_m = {need:.3f} m; the ascent ends (obstacle)",
              ascent_end="obstacle")
        return go(P.ASCENT_LOWER_OBSTACLE, "tread shorter than min_tread_m")
    lifted = t.snap.turns(MotorId.MTF) - _lf(t).return_mtf
    rise = (lifted - ctx.number_of_vertical_turns) * cfg.motors.lift_travel_per_turn \
        + cfg.sensors.front_height
    if tread is not None and tread != float("inf") and rise < cfg.min_rise_for(tread) \
            and not _held(t, w, tread):
        # A cone looking up sees over the next riser (as high as this one, we
        # assume) this far away: the readings mix what lies beyond it.
        ctx.ascent_end = AscentEnd.OBSTACLE
        t.say(f"step {ctx.number_of_steps + 1} is too low for its tread: rise about {rise:.3f} "
              f"m < {cfg.min_rise_for(tread):.3f} m (the front cone's top, "
              f"{math.degrees(cfg.front_cone_top_rad):.1f}° up, would see over the next riser "
              f"{tread:.3f} m away); the ascent ends (obstacle)", ascent_end="obstacle")
        return go(P.ASCENT_LOWER_OBSTACLE, "rise too low for the tread the front cone measures")
    ctx.number_of_turns_for_step_height = lifted
    if ctx.number_of_steps < len(ctx.tread_length):
        ctx.tread_length[ctx.number_of_steps] = \
            None if tread is None or tread == float("inf") else tread
    if narrow(cfg, tread):
        t.say(f"step {ctx.number_of_steps + 1} is narrow: tread {tread:.3f} m < "
              f"LENGTH_OF_A_ROBOT + SAFE_LENGTH: segment 3 stays in the air over the step "
              "below until segment 1 is on the next (narrow_steps)")
    _measure_next_step(t, w)
    t.say(f"number_of_turns_for_step_height = {ctx.number_of_turns_for_step_height:.2f} "
          f"(step {ctx.number_of_steps + 1})",
          number_of_turns_for_step_height=ctx.number_of_turns_for_step_height)
    return go(P.ASCENT_DRIVE_FIRST)


def _held(t: Tick, w: SightWork, tread: float) -> bool:
    """A tread past FAR_TREAD_M whose rise is below min_rise_for: whether the
    pair's readings held as segment 1 rose (a wall, or a riser the cone
    sees whole: climbed), said either way
    (:mod:`~stairbot.control.algorithm.long_tread`)."""
    if not long_tread.far(tread):
        return False
    reading = tread + _gap(t)
    held, moved = long_tread.steady(t, w, reading)
    limit = long_tread.steady_m(t, reading)
    lift_mm = t.ctx.number_of_vertical_turns * t.cfg.motors.lift_travel_per_turn * 1000
    if moved is None:
        t.say(f"step {t.ctx.number_of_steps + 1}: too few readings past the riser over the "
              f"last {lift_mm:.0f} mm of lift to tell whether they held")
    else:
        t.say(f"step {t.ctx.number_of_steps + 1}: the front pair's readings of the riser "
              f"{reading:.3f} m ahead moved {moved * 1000:.0f} mm as segment 1 rose "
              f"{lift_mm:.0f} mm ({'within' if held else 'more than'} {limit * 1000:.0f} mm): "
              + ("a wall, or a riser the whole cone sees" if held
                 else "the cone sees over it"), tread_moved=moved)
    return held


def _sample_sight(t: Tick, w: SightWork) -> None:
    """Over the lift past the sight-over, keep each front reading that still
    sees past the riser in ``w.rise_rows`` (the long tread's rule), and over
    its second half in ``w.sights`` too."""
    second_half = (t.snap.turns(MotorId.MTF) - w.entry_mtf
                   >= t.ctx.number_of_vertical_turns / 2.0)
    gap, cfg = _gap(t), t.cfg
    for i, r in enumerate(motion.pair(t.snap)):
        if r.ok and not motion.far(r, cfg) and r.distance_m >= gap + SIGHT_JUMP_M:
            w.rise_rows[i].append(r.distance_m)
            if second_half:
                w.sights[i].append(r.distance_m)


def _sight_medians(t: Tick, w: SightWork) -> list[float | None]:
    """SFR's and SFL's readings past the riser: each one's median over the
    lift's second half where it has them, else its reading now; None for a
    sensor that reads nothing ahead now.  The median, not the mean: stray
    measurements that pass perception's median can hold a reading
    centimetres off for many ticks of the lift; in a mean they make
    length_of_next_step that much long, segment 2 stops short of the edge,
    and lifting segment 3 pitches the robot nose up."""
    out: list[float | None] = []
    for i, r in enumerate(motion.pair(t.snap)):
        sights = w.sights[i]
        out.append(None if motion.far(r, t.cfg) else
                   statistics.median(sights) if sights else r.distance_m)
    return out


def _tread_measured(t: Tick, w: SightWork) -> float | None:
    """:func:`tread_seen` now, on :func:`_sight_medians`."""
    tread = tread_seen(t)
    if tread is None or tread == float("inf"):
        return tread
    return min(m for m in _sight_medians(t, w) if m is not None) - _gap(t)


_more_enter, _lift_more = lift(lambda t, _w: {MotorId.MTF: t.ctx.number_of_vertical_turns},
                               _lifted_first)


def _more_step(t: Tick, w: SightWork) -> Step:
    _sample_sight(t, w)
    return _lift_more(t, w)


LIFT_FIRST_MORE = PhaseDef(
    P.ASCENT_LIFT_FIRST_MORE, "ascent 3 — lift segment 1: number_of_vertical_turns more", FLOW,
    _more_step, SightWork, enter=_more_enter, carried_by=(2, 3), family=LiftFirst,
    to={P.ASCENT_DRIVE_FIRST: "turns made; reading − gap ≥ min_tread_m: "
                              "number_of_turns_for_step_height stored",
        P.ASCENT_LOWER_OBSTACLE: "turns made; reading − gap < min_tread_m: "
                                 "tread too short; or a rise too low for the tread "
                                 "(min_rise_for; past FAR_TREAD_M, only if the readings "
                                 "grew as segment 1 rose)",
        P.ERROR: FAULT})


def _lowered_obstacle(t: Tick, _w: LiftWork) -> Step:
    if landing.can_scan(t, _lf(t).wall_ahead):
        # a wall ahead at the top of a flight may be a landing's: look sideways first
        return go(P.LANDING_SCAN)
    if landing.turned_here(t):
        # the next flight's first step refused: back where it turned, and turn back
        return go(P.LANDING_RETURN)
    return go(P.DESCENT_BACK_OFF if t.ctx.number_of_steps > 0 else P.DESCENT_FINISH)


_obstacle_enter, _obstacle_step = lift(
    lambda t, w: {MotorId.MTF: _lf(t).return_mtf - w.entry_mtf}, _lowered_obstacle)
LOWER_OBSTACLE = PhaseDef(
    P.ASCENT_LOWER_OBSTACLE, "ascent 3 — step too high: lower segment 1", FLOW, _obstacle_step,
    LiftWork, enter=_obstacle_enter, carried_by=(2, 3), family=LiftFirst,
    to={P.DESCENT_BACK_OFF: "lowered; number_of_steps > 0",
        P.LANDING_SCAN: "lowered; number_of_steps > 0, [algorithm] landings and no landing "
                        "scanned yet: look sideways for the next flight",
        P.LANDING_RETURN: "lowered; the first step after a landing's turn: back to where it "
                          "turned",
        P.DESCENT_FINISH: "lowered; number_of_steps = 0", P.ERROR: FAULT})


# -- ascent 4-7: segment by segment onto the step -------------------------------------------
def _measure_next_step(t: Tick, w: SightWork) -> None:
    """Ascent 4's "store the reading in length_of_next_step", on the pair's
    medians over ascent 3's last lift (:func:`_sight_medians`) rather than one
    reading: a Sharp's single reading at 0.35 m is 8 mm off one time in
    five, and segment 2 would stop that short of the edge."""
    ctx = t.ctx
    medians = _sight_medians(t, w)
    if motion.measurable(t.snap, t.cfg) and None not in medians:
        ctx.length_of_next_step = sum(m for m in medians if m is not None) / 2.0
        far = long_tread.far(ctx.length_of_next_step)
        t.say(f"length_of_next_step = {ctx.length_of_next_step:.3f} m"
              + (f" (past FAR_TREAD_M = {long_tread.FAR_TREAD_M} m: the drives onto the step "
                 "go by turns)" if far else ""),
              length_of_next_step=ctx.length_of_next_step)
        return
    ctx.length_of_next_step = None
    t.say("length_of_next_step not measurable (nothing ahead within LENGTH_OF_INFINITY): "
          "driving NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE turns", length_of_next_step=None)


def _first_target(t: Tick) -> float | None:
    length = long_tread.near_length(t)
    return None if length is None else length - t.cfg.LENGTH_OF_FIRST_MODULE


def _second_target(t: Tick) -> float | None:
    length = long_tread.near_length(t)
    if length is None:
        return None
    return length - t.cfg.LENGTH_OF_FIRST_MODULE - t.cfg.LENGTH_OF_SECOND_MODULE


def _third_target(t: Tick) -> float | None:
    """length_of_next_step − LENGTH_OF_A_ROBOT, or, on a narrow step (which
    the robot does not fit on), no nearer the next riser than a tread of
    min_tread_m would leave it (SAFE_LENGTH and the approach's gap): segment
    3 stays in the air over the step below.  None (by turns) past
    FAR_TREAD_M, as for ascent 4 and 6."""
    length = long_tread.near_length(t)
    if length is None:
        return None
    cfg = t.cfg
    return max(length - cfg.LENGTH_OF_A_ROBOT, cfg.SAFE_LENGTH + cfg.algorithm.approach_gap)


def _h(t: Tick) -> float:
    return t.ctx.number_of_turns_for_step_height


def _driven_first(t: Tick, _w: DriveWork) -> Step:
    # segment 3, in the air over the step below if that is narrow, has rolled on with the
    # robot onto the tread behind the riser just climbed: it carries again
    t.ctx.third_in_air = False
    return go(P.ASCENT_LIFT_SECOND)


DRIVE_FIRST = drive_phase(
    P.ASCENT_DRIVE_FIRST, "ascent 4 — drive segment 1 onto the step", FLOW, 1, _first_target,
    lambda t: t.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE, P.ASCENT_LIFT_SECOND,
    "reads length_of_next_step − LENGTH_OF_FIRST_MODULE (or turns made); from a narrow "
    "step, segment 3 on its tread again", _driven_first, work=DriveWork)

LIFT_SECOND = lift_phase(
    P.ASCENT_LIFT_SECOND, "ascent 5 — lift segment 2", FLOW,
    lambda t, _w: {MotorId.MTF: -_h(t), MotorId.MTB: -_h(t)}, P.ASCENT_DRIVE_SECOND, (1, 3))

DRIVE_SECOND = drive_phase(
    P.ASCENT_DRIVE_SECOND, "ascent 6 — drive segment 2 onto the step", FLOW, 1, _second_target,
    lambda t: t.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_SECOND_MODULE, P.ASCENT_LIFT_THIRD,
    "reads length_of_next_step − LENGTH_OF_FIRST_MODULE − LENGTH_OF_SECOND_MODULE "
    "(or turns made)", work=DriveWork)


def _lifted_third(t: Tick, _w: LiftWork) -> Step:
    ctx, cfg = t.ctx, t.cfg
    i = ctx.number_of_steps
    if motion.measurable(t.snap, cfg):
        ctx.tab_length_to_edge[i] = motion.mean_distance(t.snap)
        t.say(f"tab_length_to_edge[{i}] = {ctx.tab_length_to_edge[i]:.3f} m",
              index=i, tab_length_to_edge=ctx.tab_length_to_edge[i])
    else:
        ctx.tab_length_to_edge[i] = None
        t.say(f"tab_length_to_edge[{i}] not measurable (nothing ahead): the descent of this "
              "step drives by turns", index=i, tab_length_to_edge=None)
    ctx.number_of_steps += 1
    t.say(f"number_of_steps = {ctx.number_of_steps}", number_of_steps=ctx.number_of_steps)
    return go(P.ASCENT_CHECK)


_lift3 = lift(lambda t, _w: {MotorId.MTB: _h(t)}, _lifted_third)
LIFT_THIRD = PhaseDef(
    P.ASCENT_LIFT_THIRD, "ascent 7 — lift segment 3", FLOW, _lift3[1], LiftWork, enter=_lift3[0],
    watches="front", carried_by=(1, 2),
    to={P.ASCENT_CHECK: "turns made; tab_length_to_edge[i] stored, number_of_steps + 1",
        P.ERROR: FAULT})


# -- ascent 8-9: the top, or the next step ------------------------------------------------------
TAB_WAIT_S = 1.0
"""Ascent 8: how long the robot stands for a tab ascent 7 found not
measurable while the pair does not read "nothing ahead" either."""


def _check(t: Tick, w: WaitWork) -> Step:
    ctx, cfg = t.ctx, t.cfg
    sfr, sfl = motion.pair(t.snap)
    if motion.far(sfr, cfg) and motion.far(sfl, cfg):
        ctx.ascent_end = AscentEnd.TOP_REACHED
        t.say(f"top reached after {ctx.number_of_steps} steps: SFR/SFL read at least "
              "LENGTH_OF_INFINITY; the descent begins", ascent_end="top_reached")
        return go(P.DESCENT_LOWER_THIRD)
    tab = _tab_again(t, w)
    if tab is not None:
        return tab
    if ctx.number_of_steps >= cfg.algorithm.max_steps:
        ctx.ascent_end = AscentEnd.STEP_LIMIT
        t.say(f"number_of_steps reached {cfg.algorithm.max_steps}: the ascent ends; "
              "the descent begins", ascent_end="step_limit")
        return go(P.DESCENT_LOWER_THIRD)
    return go(P.ASCENT_DRIVE_THIRD)


def _tab_again(t: Tick, w: WaitWork) -> Step | None:
    """Ascent 7 found no tab (one sensor at least read nothing ahead) and
    the pair does not read "nothing ahead" now: a riser about
    LENGTH_OF_INFINITY away, which one beam reaches and the other not.  The
    descent of this step reads it: stand up to TAB_WAIT_S for the pair to
    read it (kept), or both nothing (the top); still neither, go on, and
    descent 1 finds this step's edge by the back pair alone.  The wait gives
    descent 1 a tab to back to where one can be read.  The split reading is
    not taken for the top: one sensor reading a little long, the robot askew
    at the flight's side, would then end the ascent, and coming down the
    step it stands on from there tips the robot back.  None: go on."""
    ctx, cfg = t.ctx, t.cfg
    i = ctx.number_of_steps - 1
    if not 0 <= i < len(ctx.tab_length_to_edge) or ctx.tab_length_to_edge[i] is not None:
        return None
    if motion.measurable(t.snap, cfg):
        ctx.tab_length_to_edge[i] = motion.mean_distance(t.snap)
        t.say(f"tab_length_to_edge[{i}] = {ctx.tab_length_to_edge[i]:.3f} m (read standing at "
              "ascent 8: ascent 7 read nothing ahead)", index=i,
              tab_length_to_edge=ctx.tab_length_to_edge[i])
        return None
    if w.still_since is None:
        w.still_since = t.snap.time_s
    if t.snap.time_s - w.still_since < TAB_WAIT_S:
        return stay(NO_MOTION)
    sfr, sfl = motion.pair(t.snap)
    t.say(f"tab_length_to_edge[{i}] not measured: SFR/SFL read {sfr.distance_m:.3f}/"
          f"{sfl.distance_m:.3f} m for {TAB_WAIT_S:g} s, not both a riser nor both nothing "
          "ahead; going on (the descent of this step finds its edge by the back pair alone)")
    return None  # the phase goes on this tick


CHECK = PhaseDef(
    P.ASCENT_CHECK, "ascent 8 — check the distance (top?)", FLOW, _check, WaitWork,
    watches="front",
    to={P.DESCENT_LOWER_THIRD: "reads ≥ LENGTH_OF_INFINITY (top reached) "
                               "or number_of_steps = max_steps",
        P.ASCENT_DRIVE_THIRD: "otherwise",
        P.ERROR: FAULT})


def _driven_third(t: Tick, w: DriveWork) -> Step:
    t.ctx.riser_wheel = None
    t.ctx.third_in_air = narrow(t.cfg, t.ctx.tread_length[t.ctx.number_of_steps - 1])
    if w.target_reading is not None and not w.reading_lost and w.target_wheel is not None:
        # where the last readings put the riser: ascent 2 starts from it if
        # the sensors cannot read that near
        t.ctx.riser_wheel = w.target_wheel + t.cfg.wheel_turns(w.target_reading)
    return calibrate(Purpose.ASCENT)


DRIVE_THIRD = drive_phase(
    P.ASCENT_DRIVE_THIRD, "ascent 9 — drive segment 3 onto the step", FLOW, 1, _third_target,
    lambda t: t.cfg.wheel_turns(t.cfg.LENGTH_OF_THIRD_MODULE), P.CAL_CHECK,
    "reads length_of_next_step − LENGTH_OF_A_ROBOT, on a narrow step SAFE_LENGTH + "
    "approach_gap (or turns made): next step, ascent 1", _driven_third, work=DriveWork)

PHASES: tuple[PhaseDef[Any], ...] = (
    APPROACH, APPROACH_TURNS, LIFT_FIRST, LIFT_FIRST_MORE, LOWER_OBSTACLE, DRIVE_FIRST,
    LIFT_SECOND, DRIVE_SECOND, LIFT_THIRD, CHECK, DRIVE_THIRD,
)
