"""Calibration's turns on segment 2's wheels (segments 1 and 3 lifted): the
squaring turn, case 3's probe and the corner, turning away (case 3B), and
turning back to a heading (descent 1 and 7).  The rest of calibration, and
the helpers both share: :mod:`~stairbot.control.algorithm.calibration`.
"""

from __future__ import annotations

from typing import Any

from stairbot.control.algorithm import motion
from stairbot.control.algorithm.calibration import FLOW
from stairbot.control.algorithm.families import Calibration
from stairbot.control.algorithm.modes import LANDING_PURPOSES, CalibrationCase, Purpose
from stairbot.control.algorithm.phase import (
    FAILED,
    FAULT,
    NO_MOTION,
    Exit,
    PhaseDef,
    Step,
    Tick,
    distrust,
    fail,
    go,
    stay,
    where,
)
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.squaring import (
    LANDING_TURN_MARGIN_RAD,
    MAX_AWAY_YAW_RAD,
    MAX_SQUARE_YAW_RAD,
    MAX_TURN_FLIPS,
    MAX_TURN_YAW_RAD,
    PROBE_TICKS,
    PROBE_YAW_RAD,
    STILL_TICKS,
    TURN_MARGIN_RAD,
    TURN_SLOW_FLOOR,
    askew_rad,
    heading_off_rad,
    mean_diff,
    measured_standing,
    one_riser,
    readings,
    settled,
    trimmed_mean,
)
from stairbot.control.algorithm.squaring_bias import beyond, past
from stairbot.control.algorithm.texts import calibration as say
from stairbot.control.algorithm.work import AwayWork, CornerWork, ProbeWork, TurnWork, Work
from stairbot.control.tolerances import pair_tolerance, still_samples, still_tolerance
from stairbot.hardware import FRONT_SENSORS, MotorId, SensorStatus

P = Phase


# -- turning ---------------------------------------------------------------------------
def _turned_too_far(t: Tick, phase: Phase) -> Step | None:
    made = abs(t.snap.turns(MotorId.MWR) - t.cal.turn_origin)
    limit = MAX_TURN_YAW_RAD
    if t.cal.purpose in LANDING_PURPOSES:
        limit += LANDING_TURN_MARGIN_RAD  # a landing's turn is 90° by the odometer
    if motion.turn_yaw_rad(t.cfg, made) <= limit:
        return None
    return fail(say.turned_too_far(where(t.ctx, phase), limit))


def _turn_enter(t: Tick, w: TurnWork) -> None:
    r, l_ = motion.pair(t.snap)
    sfr, sfl = r.distance_m, l_.distance_m
    # SFL < SFR: the left side is nearer, turn left (the seed's case 2 rule).
    w.turn_direction = 1 if sfl < sfr else -1
    w.turn_diff = sfl - sfr
    # Both beams on one riser, the difference says how far the robot is turned
    # from square to it: the turn may make that and a margin, no more.
    w.turn_from = t.snap.turns(MotorId.MWR)
    w.turn_first = w.turn_seen = (sfr, sfl)
    if motion.far(r, t.cfg) or motion.far(l_, t.cfg):
        # one beam off the flight's side: no figure, at most as askew as a
        # calibration may stand
        w.turn_limit_rad = MAX_SQUARE_YAW_RAD + TURN_MARGIN_RAD
    else:
        # the larger of what the standing mean the case was chosen on says and
        # what the readings now say: one tick of a noisy pair (a Sharp pair at
        # 0.36 m) can read nearly square where the mean said 16 deg askew
        diff = max(abs(sfl - sfr), abs(t.cal.case_diff or 0.0))
        w.turn_limit_rad = askew_rad(t.cfg, diff) + TURN_MARGIN_RAD


def _turned_past_limit(t: Tick, w: TurnWork) -> Step | None:
    made = motion.turn_yaw_rad(t.cfg, abs(t.snap.turns(MotorId.MWR) - w.turn_from))
    if made <= w.turn_limit_rad:
        return None
    return _held_through(t, w, made) or fail(
        say.turned_past_first_readings(where(t.ctx, P.CAL_TURN), made, w.turn_limit_rad))


def _follow(t: Tick, w: TurnWork) -> None:
    """Whether SFR and SFL still read what they read at the turn's start
    (a distance, or "nothing within range" or "too near" at the clamp), how
    far each has moved from it reading a distance, and the last distance
    each read."""
    now = [(r.distance_m, r.status is not SensorStatus.ERROR, not motion.far(r, t.cfg))
           for r in motion.pair(t.snap)]
    held = [h and ok and d == f for h, (d, ok, _), f in zip(w.turn_held, now, w.turn_first,
                                                             strict=True)]
    moved = [max(m, abs(d - f)) if ok and near else m
             for m, (d, ok, near), f in zip(w.turn_moved, now, w.turn_first, strict=True)]
    seen = [d if ok and near else s for s, (d, ok, near) in zip(w.turn_seen, now, strict=True)]
    w.turn_held, w.turn_moved = (held[0], held[1]), (moved[0], moved[1])
    w.turn_seen = (seen[0], seen[1])


def _held_through(t: Tick, w: TurnWork, made: float, gone: bool = False) -> Step | None:
    """Descent 1 on a climbed step, turned past what the first readings
    allow -- or, ``gone``, turned until both beams read nothing ahead, which
    no heading square to the riser the robot climbed gives: a front sensor
    that read one value on every tick of the turn while its partner read
    the riser and moved by more than the pair's noise is stuck (a turn on
    the spot moves what both look at; a value held through it, "nothing
    within range" included, beside a partner that sees the riser the robot
    climbed, is not a reading).  A partner gone to nothing ahead has turned
    its beam off the riser's face: an HC-SR04 hears no echo from a surface
    turned more than its `echo_incidence_deg` away.  Judged once; the robot
    then limps home on the partner, back on the heading it climbed the step
    with (:func:`_turn`)."""
    ctx, cfg = t.ctx, t.cfg
    if w.distrusted or t.cal.purpose is not Purpose.DESCENT or ctx.from_top \
            or ctx.climb_twist[t.descent_index] is None:
        return None
    pair = motion.pair(t.snap)
    for i, sid in enumerate(FRONT_SENSORS):
        partner, first = pair[1 - i], w.turn_first[1 - i]
        seen = partner.ok and not motion.far(partner, cfg)
        if not w.turn_held[i] or w.turn_held[1 - i] or not (seen or gone) \
                or first >= cfg.LENGTH_OF_INFINITY \
                or w.turn_moved[1 - i] <= pair_tolerance(cfg, first):
            continue
        w.distrusted = True
        return distrust(sid, say.held_through_turn(
            sid.value, w.turn_first[i], FRONT_SENSORS[1 - i].value, first,
            w.turn_seen[1 - i], made, gone=not seen))
    return None


def _limp_turn_back(t: Tick) -> Step | None:
    """A front sensor lost in descent 1's turn (:func:`_held_through`): the
    survivor reads for both, so SFR = SFL says nothing of the heading; turn
    back by the odometer to the one the step was climbed with instead."""
    ctx = t.ctx
    if ctx.limp is None or not set(ctx.limp.lost) & {s.value for s in FRONT_SENSORS} \
            or t.cal.purpose is not Purpose.DESCENT or ctx.from_top:
        return None
    climbed = ctx.climb_twist[t.descent_index]
    if climbed is None:
        return None
    t.cal.turn_to = climbed
    ctx.descent.turned_back = True
    t.say(say.limp_turn_back(heading_off_rad(t, climbed)))
    return go("limp_turn_back")


def _turn(t: Tick, w: TurnWork) -> Step:
    cfg = t.cfg
    back = _limp_turn_back(t)
    if back is not None:
        return back
    _follow(t, w)
    sfr, sfl = readings(t)
    if not w.measuring and w.turn_held[0] == w.turn_held[1] and past(t):
        # not squaring to the riser, and neither sensor held one value through
        # the turn (the stuck rule's case, :func:`_held_through`): one of the
        # pair reads an offset, and nothing names which
        chased = beyond(t)
        if chased is not None:
            return chased
    if w.measuring:  # stopped at SFR = SFL: measuring standing still, once settled
        if not settled(t, w):
            return stay(NO_MOTION)
        # as long as it takes to know the difference to within equal_tolerance
        if not measured_standing(t, w, max(STILL_TICKS, still_samples(cfg, min(sfr, sfl)))):
            return stay(NO_MOTION)
        if not w.diffs:  # not one tick read both: the check on all wheels says what follows
            t.cal.beams_lost_rad = motion.turn_yaw_rad(
                cfg, abs(t.snap.turns(MotorId.MWR) - w.turn_from))
        diff = mean_diff(t, w)
        if abs(diff) <= still_tolerance(cfg, max(1, len(w.diffs)), min(sfr, sfl)):
            t.say(say.squared_up(diff, len(w.diffs), sfr, sfl), SFR=sfr, SFL=sfl, diff=diff)
            t.cal.squaring_turns += 1
            return go("square")
        # Not square yet: turn on, slowly, the way the difference says.
        direction = 1 if diff < 0 else -1  # as on entry: SFL nearer, turn left
        if direction != w.turn_direction:
            w.turn_flips += 1
            if w.turn_flips > MAX_TURN_FLIPS:
                return fail(say.turned_back_and_forth(where(t.ctx, P.CAL_TURN), MAX_TURN_FLIPS,
                                                      diff, sfr, sfl))
        w.measuring, w.diffs, w.diff_skipped, w.still_since = False, [], 0, None
        w.turn_direction = direction
        w.turn_diff = diff
    w.turn_diff = motion.smooth(w.turn_diff, sfl - sfr)
    # Turning left closes SFL - SFR from below, turning right from above: stop
    # when the smoothed difference has reached zero (or, with readings that
    # no longer change, has decayed to a twentieth of their resolution), then
    # check it standing still.
    remaining = -w.turn_direction * w.turn_diff
    if remaining <= cfg.sensors.resolution / 20:
        if all(motion.far(r, cfg) for r in motion.pair(t.snap)):
            made = motion.turn_yaw_rad(cfg, abs(t.snap.turns(MotorId.MWR) - w.turn_from))
            lost = _held_through(t, w, made, gone=True)
            if lost is not None:
                return lost
        w.measuring = True
        return stay(NO_MOTION)
    too_far = _turned_too_far(t, P.CAL_TURN) or _turned_past_limit(t, w)
    if too_far is not None:
        return too_far
    slow = min(1.0, max(TURN_SLOW_FLOOR, remaining / (2 * cfg.algorithm.equal_tolerance)))
    return stay(motion.turn(w.turn_direction, cfg, slow))


TURN = PhaseDef(
    P.CAL_TURN, "calibration case 2 — turn until SFR = SFL", FLOW, _turn, TurnWork,
    enter=_turn_enter, family=Calibration,
    on={"square": Exit(P.CAL_LOWER, "SFR = SFL"),
        "limp_turn_back": Exit(P.CAL_TURN_TO, "limping home, a front sensor lost in the "
                                              "turn: back to the heading the step was "
                                              "climbed with"),
        "chased": Exit(P.CAL_TURN_TO, "descent 1: turned further from the climbed heading "
                                      "than square allows, or lost both beams: back to it"),
        FAILED: Exit(P.ERROR, "turned too far, or more than its first readings allow; "
                              + FAULT)})


def _probe(t: Tick, w: ProbeWork) -> Step:
    """Lifted, measure SFR and SFL standing still, then turn left and watch
    how they change.  Both ends of the comparison are means: the start the
    trimmed mean standing, now the mean of the last PROBE_TICKS ticks.  One
    tick at each end would let a square VL53L1X pair's noise look like a
    corner (SFR growing and SFL shrinking by millimetres against a start
    reading long), and case 3B would turn far looking for a riser that is
    ahead."""
    cal, cfg = t.cal, t.cfg
    if not w.measured:
        if not settled(t, w) or not measured_standing(t, w, STILL_TICKS):
            return stay(NO_MOTION)
        if not w.standing:  # no tick gave both: now's readings, as the seed
            w.standing.append(readings(t))
        w.probe_sfr = trimmed_mean([r for r, _l in w.standing])
        w.probe_sfl = trimmed_mean([l_ for _r, l_ in w.standing])
        w.measured = True
    r, l_ = motion.pair(t.snap)
    both = r.ok and l_.ok and not motion.far(r, cfg) and not motion.far(l_, cfg)
    if both:
        w.probe_recent = [*w.probe_recent[-(PROBE_TICKS - 1):], (r.distance_m, l_.distance_m)]
        sfr = sum(r_ for r_, _l in w.probe_recent) / len(w.probe_recent)
        sfl = sum(l_ for _r, l_ in w.probe_recent) / len(w.probe_recent)
    else:
        # A beam off the riser (or past LENGTH_OF_INFINITY) is as large a
        # change as there is: now's readings.  Waiting for ticks that see
        # something, a robot well askew and far away would turn on until both
        # beams read nothing, and square up to nothing.
        sfr, sfl = readings(t)
    # a corner is decided on a full window of means only
    window_full = both and len(w.probe_recent) >= PROBE_TICKS
    made = abs(t.snap.turns(MotorId.MWR) - cal.turn_origin)
    d_sfr, d_sfl = sfr - w.probe_sfr, sfl - w.probe_sfl
    # Half a resolution step off the readings' grid: whole-millimetre readings
    # that sum to the threshold exactly must not be decided by float rounding
    # (the simulation's and the wire's last bits differ).
    tol = cfg.algorithm.equal_tolerance + cfg.sensors.resolution / 4
    # A corner only if the changes exceed the pair's noise at the distance
    # (pair_tolerance), not equal_tolerance alone; a corner's look within the
    # noise is probed further, not decided.
    corner_tol = max(tol, pair_tolerance(cfg, (w.probe_sfr + w.probe_sfl) / 2.0))
    cornerish = d_sfr > 0 and d_sfl < 0
    unsure = abs(d_sfr) + abs(d_sfl) < 2 * tol or (
        cornerish and (not window_full or d_sfr - d_sfl < corner_tol))
    if unsure and motion.turn_yaw_rad(cfg, made) < PROBE_YAW_RAD:
        return stay(motion.turn(1, cfg))
    corner = cornerish and d_sfr - d_sfl >= corner_tol
    cal.case = CalibrationCase.THREE_B if corner else CalibrationCase.THREE_A
    data = {"case": cal.case.value, "dSFR": d_sfr, "dSFL": d_sfl}
    if corner:
        t.say(say.case_3b(d_sfr, d_sfl), **data)
        return go("case_3b")
    t.say(say.case_3a(d_sfr, d_sfl), **data)
    return go("case_3a")


PROBE = PhaseDef(
    P.CAL_PROBE, "calibration case 3 — probe turn left (A or B?)", FLOW, _probe, ProbeWork,
    family=Calibration,
    on={"case_3b": Exit(P.CAL_CORNER, "SFR grew, SFL shrank: case 3B"),
        "case_3a": Exit(P.CAL_TURN, "otherwise: case 3A, turn back right"),
        FAILED: Exit(P.ERROR, FAULT)})


def _corner_enter(t: Tick, w: CornerWork) -> None:
    w.largest_sfr = readings(t)[0]


def _corner(t: Tick, w: CornerWork) -> Step:
    sfr, _sfl = readings(t)
    w.largest_sfr = max(w.largest_sfr, sfr)
    if sfr < w.largest_sfr - t.cfg.algorithm.equal_tolerance:
        t.say(say.corner_shrinks(sfr))
        return go("both_shrink")
    too_far = _turned_too_far(t, P.CAL_CORNER)
    if too_far is not None:
        return too_far
    return stay(motion.turn(1, t.cfg))


CORNER = PhaseDef(
    P.CAL_CORNER, "calibration case 3B — turn left until both readings shrink", FLOW, _corner,
    CornerWork, enter=_corner_enter, family=Calibration,
    on={"both_shrink": Exit(P.CAL_TURN, "both readings shrink"),
        FAILED: Exit(P.ERROR, "turned too far; " + FAULT)})


def _away_enter(t: Tick, w: AwayWork) -> None:
    sfr, sfl = readings(t)
    # The nearer beam sees a side wall: turn away from it (left when SFR is
    # the nearer), the opposite of case 2's rule, until it sees the riser.
    w.turn_direction = 1 if sfr < sfl else -1
    w.turn_diff = sfl - sfr
    w.turn_from = t.snap.turns(MotorId.MWR)


def _away(t: Tick, w: AwayWork) -> Step:
    """Off the wall, the beam that saw it reads the riser: the pair flips
    (the other sensor is now the nearer, the robot still askew the same way)
    and the squaring turn goes on in the same direction.  Askew by less than
    the pair can tell, it flips and flips back as the robot passes square."""
    cfg = t.cfg
    r, l_ = motion.pair(t.snap)
    sfr, sfl = r.distance_m, l_.distance_m
    first = w.turn_direction  # the sign of SFL − SFR at the start
    w.turn_diff = motion.smooth(w.turn_diff, sfl - sfr)
    d = w.turn_diff
    seen = not motion.far(r, cfg) and not motion.far(l_, cfg)
    flipped = d * first < 0
    w.flipped = w.flipped or flipped
    off_wall = flipped and abs(d) >= cfg.algorithm.equal_tolerance
    passed_square = w.flipped and not flipped and abs(d) <= one_riser(cfg)
    if seen and (off_wall or passed_square):
        t.say(say.off_side_wall(sfr, sfl), SFR=sfr, SFL=sfl)
        return go("off_wall")
    made = motion.turn_yaw_rad(cfg, abs(t.snap.turns(MotorId.MWR) - w.turn_from))
    if made > MAX_AWAY_YAW_RAD:
        return fail(say.away_too_far(where(t.ctx, P.CAL_AWAY), MAX_AWAY_YAW_RAD, sfr, sfl))
    return stay(motion.turn(w.turn_direction, cfg))


AWAY = PhaseDef(
    P.CAL_AWAY, "calibration case 2W — turn away from the side wall until both see the riser",
    FLOW, _away, AwayWork, enter=_away_enter, family=Calibration,
    on={"off_wall": Exit(P.CAL_TURN, "off the wall: the pair flipped (or flipped back, "
                                     "square)"),
        FAILED: Exit(P.ERROR, "turned too far; " + FAULT)})


# -- turn back to a heading (descent 1 and 7) ------------------------------------------
def _turn_to(t: Tick, w: Work) -> Step:
    """Turn on segment 2's wheels until the odometer's heading is the
    calibration's ``turn_to``."""
    turn_to = t.cal.turn_to
    assert turn_to is not None  # set by whoever lifted for this turn
    remaining = turn_to - motion.twist(t.snap)
    if abs(remaining) <= motion.WHEEL_DONE:
        return go("turned")
    too_far = _turned_too_far(t, P.CAL_TURN_TO)
    if too_far is not None:
        return too_far
    # braking as a drive does, from the turning speed
    top = min(motion.TURN_SPEED, t.cfg.motors.wheel_speed)
    speed = motion.approach(top, abs(remaining), motion.WHEEL_BRAKE_ZONE, t.cfg.algorithm.tick)
    return stay(motion.turn(1 if remaining > 0 else -1, t.cfg, speed / top))


TURN_TO = PhaseDef(
    P.CAL_TURN_TO, "calibration — turn by the odometer to a heading", FLOW,
    _turn_to, Work, family=Calibration,
    on={"turned": Exit(P.CAL_LOWER, "turned to it"),
        FAILED: Exit(P.ERROR, "turned too far; " + FAULT)})

PHASES: tuple[PhaseDef[Any], ...] = (PROBE, CORNER, AWAY, TURN, TURN_TO)
