"""Ascent 3: lift segment 1 until the front sensors see over the step, then
number_of_vertical_turns more, measuring the tread past the riser; h
(number_of_turns_for_step_height) is the total.  A step too high (a wall), a
tread too short, or a rise too low for the tread the front cone measures
ends the ascent: segment 1 is lowered again (the obstacle).  The phases
share :class:`~stairbot.control.algorithm.families.LiftFirst`.
"""

from __future__ import annotations

import statistics

from stairbot.control.algorithm import landing, limits, long_tread, lost, motion
from stairbot.control.algorithm.families import LiftFirst
from stairbot.control.algorithm.modes import AscentEnd
from stairbot.control.algorithm.moves import lift, stood
from stairbot.control.algorithm.phase import (
    FAILED,
    FAULT,
    NO_MOTION,
    Exit,
    PhaseDef,
    Step,
    Tick,
    go,
    stay,
)
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.texts import ascent as say
from stairbot.control.algorithm.work import LiftFirstWork, LiftWork, SightWork
from stairbot.control.tolerances import settle_s
from stairbot.hardware import MotorId
from stairbot.inputs.config import RobotConfig

P = Phase
FLOW = "ascent"

SIGHT_JUMP_M = 0.05
"""Ascent 3: the front sensors see over the riser when both read at least this
much past it (or nothing ahead).  No tread is this short, and it is ten
times the sensors' noise: a noisy reading of the riser never passes for it."""


LIMP_UNDO = {"limp_home": Exit(P.ASCENT_LOWER_OBSTACLE, lost.LIMP + ": undo the step, "
                                                                 "lower segment 1")}

# -- ascent 3: lift segment 1 -------------------------------------------------------------
def _lf(t: Tick) -> LiftFirst:
    return t.ctx.family_of(LiftFirst)


def _lift_first_enter(t: Tick, w: LiftFirstWork) -> None:
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


def _lift_first(t: Tick, w: LiftFirstWork) -> Step:
    ctx, cfg = t.ctx, t.cfg
    if lost.limping(t):
        return go("limp_home")
    if tread_seen(t) is not None:
        sfr, sfl = (r.distance_m for r in motion.pair(t.snap))
        lifted = t.snap.turns(MotorId.MTF) - _lf(t).return_mtf
        rise = lifted * cfg.motors.lift_travel_per_turn + cfg.sensors.front_height
        t.say(say.sees_over(ctx.number_of_steps, lifted, rise, sfr, sfl), rise=rise)
        if rise >= limits.min_step_rise_m(cfg):
            return go("sees_over")
        ctx.ascent_end = AscentEnd.OBSTACLE
        t.say(say.too_low_to_climb(ctx.number_of_steps, rise, limits.min_step_rise_m(cfg)),
              ascent_end="obstacle")
        return go("rise_too_low", say.RISE_TOO_LOW)
    assert w.target_mtf is not None
    speed = motion.lift_to(cfg, t.snap, MotorId.MTF, w.target_mtf)
    if speed is None:
        # At the top of its travel: the pair reports what it sees there its
        # latency and its median's majority late.  A riser the beams rose
        # past just before is seen over only then: stand, the lift holding,
        # until the filtered readings stand for the top (settle_s).
        if not stood(t, w, settle_s(cfg)):
            return stay(NO_MOTION)
        ctx.ascent_end = AscentEnd.OBSTACLE
        _lf(t).wall_ahead = True
        allowed = cfg.MAX_OF_VERTICAL_TURNS - ctx.number_of_vertical_turns
        t.say(say.too_high(ctx.number_of_steps, allowed), ascent_end="obstacle")
        return go("too_high")
    return stay({MotorId.MTF: speed})


LIFT_FIRST = PhaseDef(
    P.ASCENT_LIFT_FIRST, "ascent 3 — lift segment 1", FLOW, _lift_first, LiftFirstWork,
    enter=_lift_first_enter, carried_by=(2, 3), family=LiftFirst,
    on={"sees_over": Exit(P.ASCENT_LIFT_FIRST_MORE, "sees over the riser (reads ≥ gap + "
                                                    "SIGHT_JUMP_M)"),
        "too_high": Exit(P.ASCENT_LOWER_OBSTACLE, "MAX_OF_VERTICAL_TURNS − "
                                                  "number_of_vertical_turns made: step too high"),
        "rise_too_low": Exit(P.ASCENT_LOWER_OBSTACLE, "sees over a rise < min_step_rise_m"),
        **LIMP_UNDO,
        FAILED: Exit(P.ERROR, FAULT)})


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
    t.say(say.tread_ahead(ctx.number_of_steps, tread, _gap(t)),
          tread=None if tread is None or tread == float("inf") else tread)
    if tread is not None and tread < need:
        ctx.ascent_end = AscentEnd.OBSTACLE
        t.say(say.tread_too_short(ctx.number_of_steps, tread, need), ascent_end="obstacle")
        return go("tread_too_short", say.TREAD_TOO_SHORT)
    lifted = t.snap.turns(MotorId.MTF) - _lf(t).return_mtf
    rise = (lifted - ctx.number_of_vertical_turns) * cfg.motors.lift_travel_per_turn \
        + cfg.sensors.front_height
    if tread is not None and tread != float("inf") and rise < cfg.min_rise_for(tread) \
            and not _held(t, w, tread):
        # A cone looking up sees over the next riser (as high as this one, we
        # assume) this far away: the readings mix what lies beyond it.
        ctx.ascent_end = AscentEnd.OBSTACLE
        t.say(say.too_low_for_tread(ctx.number_of_steps, rise, cfg.min_rise_for(tread),
                                    cfg.front_cone_top_rad, tread), ascent_end="obstacle")
        return go("too_low_for_tread", say.TOO_LOW_FOR_TREAD)
    ctx.number_of_turns_for_step_height = lifted
    if ctx.number_of_steps < len(ctx.tread_length):
        ctx.tread_length[ctx.number_of_steps] = \
            None if tread is None or tread == float("inf") else tread
    if narrow(cfg, tread):
        assert tread is not None  # narrow only on a measured tread
        t.say(say.narrow_step(ctx.number_of_steps, tread))
    _measure_next_step(t, w)
    t.say(say.step_height(ctx.number_of_turns_for_step_height, ctx.number_of_steps),
          number_of_turns_for_step_height=ctx.number_of_turns_for_step_height)
    return go("measured")


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
    lift_m = t.ctx.number_of_vertical_turns * t.cfg.motors.lift_travel_per_turn
    if moved is None:
        t.say(say.too_few_readings(t.ctx.number_of_steps, lift_m))
    else:
        t.say(say.readings_held(t.ctx.number_of_steps, reading, moved, lift_m, held, limit),
              tread_moved=moved)
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


def _more_deltas(t: Tick, w: LiftWork) -> dict[MotorId, float]:
    """number_of_vertical_turns more, within MTF's stroke: a riser seen over
    only as segment 1 stood at the top of its lift (MAX_OF_VERTICAL_TURNS
    less them, within LIFT_DONE) leaves no more than the rest of the stroke,
    and a target past its end is never reached."""
    return {MotorId.MTF: min(t.ctx.number_of_vertical_turns,
                             t.cfg.MAX_OF_VERTICAL_TURNS - w.entry_mtf)}


_more_enter, _lift_more = lift(_more_deltas, _lifted_first)


def _more_step(t: Tick, w: SightWork) -> Step:
    if lost.limping(t):
        return go("limp_home")
    _sample_sight(t, w)
    return _lift_more(t, w)


LIFT_FIRST_MORE = PhaseDef(
    P.ASCENT_LIFT_FIRST_MORE, "ascent 3 — lift segment 1: number_of_vertical_turns more", FLOW,
    _more_step, SightWork, enter=_more_enter, carried_by=(2, 3), family=LiftFirst,
    on={"measured": Exit(P.ASCENT_DRIVE_FIRST, "turns made; reading − gap ≥ min_tread_m: "
                                               "number_of_turns_for_step_height stored"),
        "tread_too_short": Exit(P.ASCENT_LOWER_OBSTACLE, "turns made; reading − gap < "
                                                         "min_tread_m: tread too short"),
        "too_low_for_tread": Exit(P.ASCENT_LOWER_OBSTACLE, "turns made; a rise too low for the "
                                                           "tread (min_rise_for; past "
                                                           "FAR_TREAD_M, only if the readings "
                                                           "grew as segment 1 rose)"),
        **LIMP_UNDO,
        FAILED: Exit(P.ERROR, FAULT)})


def _lowered_obstacle(t: Tick, _w: LiftWork) -> Step:
    if t.ctx.limp is None and landing.can_scan(t, _lf(t).wall_ahead):
        # a wall ahead at the top of a flight may be a landing's: look sideways first
        return go("wall_at_top")
    if landing.turned_here(t):
        # the next flight's first step refused: back where it turned, and turn back
        return go("refused_after_turn")
    return go("steps_climbed" if t.ctx.number_of_steps > 0 else "no_step_climbed")


_obstacle_enter, _obstacle_step = lift(
    lambda t, w: {MotorId.MTF: _lf(t).return_mtf - w.entry_mtf}, _lowered_obstacle)
LOWER_OBSTACLE = PhaseDef(
    P.ASCENT_LOWER_OBSTACLE, "ascent 3 — step too high: lower segment 1", FLOW, _obstacle_step,
    LiftWork, enter=_obstacle_enter, carried_by=(2, 3), family=LiftFirst,
    on={"steps_climbed": Exit(P.DESCENT_BACK_OFF, "lowered; number_of_steps > 0"),
        "wall_at_top": Exit(P.LANDING_SCAN, "lowered; number_of_steps > 0, [algorithm] "
                                            "landings and no landing scanned yet: look "
                                            "sideways for the next flight"),
        "refused_after_turn": Exit(P.LANDING_RETURN, "lowered; the first step after a "
                                                     "landing's turn: back to where it turned"),
        "no_step_climbed": Exit(P.DESCENT_FINISH, "lowered; number_of_steps = 0"),
        FAILED: Exit(P.ERROR, FAULT)})


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
        t.say(say.length_of_next_step(ctx.length_of_next_step, far, long_tread.FAR_TREAD_M),
              length_of_next_step=ctx.length_of_next_step)
        return
    ctx.length_of_next_step = None
    t.say(say.LENGTH_NOT_MEASURABLE, length_of_next_step=None)


