"""Calibration: squaring up to the riser (cases 1, 2, 3A, 3B).

The same phases serve the start of the program (every case), ascent step 1 on
later steps and descent step 1 (case 2 only); ``Context.purpose`` says which.
Turning happens on segment 2's wheels with segments 1 and 3 lifted by
NUMBER_OF_VERTICAL_TURNS_FOR_CLEARANCE, slowly, and stops when the smoothed
SFL − SFR reaches zero, so that sensor noise neither stops it early nor
leaves the robot askew.
"""

from __future__ import annotations

import math

from stairbot.algorithm import motion
from stairbot.algorithm.moves import lift
from stairbot.algorithm.phase import (
    FAULT,
    NO_MOTION,
    PhaseDef,
    Step,
    Tick,
    end,
    fail,
    go,
    stay,
    where,
)
from stairbot.algorithm.phases import Mode, Phase
from stairbot.algorithm.work import Work
from stairbot.config import RobotConfig
from stairbot.hardware import MotorId
from stairbot.perception import pair_tolerance, settle_s, still_samples, still_tolerance

P = Phase
FLOW = "calibration"

PROBE_YAW_RAD = math.radians(10.0)
"""Case 3: the probe turn stops after this much yaw if the readings have not
changed by 2 × equal_tolerance before."""
PROBE_TICKS = 5
"""Case 3: the probe turn compares the mean of its last this many ticks'
readings with their mean standing before it."""
STILL_TICKS = 25
"""Calibration's check averages the pair's difference over this many ticks
(0.5 s at the 20 ms tick) before it decides between the cases."""
MAX_TURN_YAW_RAD = math.radians(90.0)
"""A calibration that turns this far without SFR = SFL ends with an error."""
MAX_SQUARE_YAW_RAD = math.radians(30.0)
"""The most the robot may stand askew of the riser at a calibration: two
readings further apart than both beams on one riser turned this far
(2 × front_lateral × tan 30°, 58 mm on the reference robot) cannot both see
the riser -- the nearer one sees a side wall (case 2W)."""
TURN_MARGIN_RAD = math.radians(12.0)
"""The squaring turn may turn this much more than the readings at its start
say it needs (noise, the mounts' offsets) before it ends with an error: it
never turns on to square up to a side wall."""
MAX_AWAY_YAW_RAD = math.radians(45.0)
"""Case 2W turns away from the side wall at most this far."""
TURN_SLOW_FLOOR = 0.1
"""The squaring turn slows near SFR = SFL, down to this fraction of its speed."""
MAX_TURN_FLIPS = 4
"""The squaring turn may reverse this many times after a check standing
still; the next reversal ends it with an error.  One beam off the flight's
side and the other reading long turned the robot back and forth 6 deg
until the phase timed out 60 s later, with no reason given (SFL 30 mm long
from the start, the robot at the flight's side after four steps askew)."""
MAX_SQUARING_TURNS = 4
"""A calibration that has turned this many times to square up (the squaring
turn, then corrections by the odometer) and still does not read SFR = SFL
standing on all wheels ends with an error."""
HEADING_TOLERANCE_RAD = math.radians(0.3)
"""Descent 1 turns back to the heading it climbed the step with, and descent
7 to the one the program began with, when the odometer says it is further
off than this (0.3 deg: 1.6 mm sideways over a 0.3 m climb)."""


def _readings(t: Tick) -> tuple[float, float]:
    sfr, sfl = motion.pair(t.snap)
    return sfr.distance_m, sfl.distance_m


def _after_calibration(t: Tick) -> Step:
    ctx = t.ctx
    if ctx.purpose == "descent":
        return go(P.DESCENT_BACK_TO_EDGE)
    if ctx.number_of_steps < len(ctx.climb_twist):
        # the heading this step is climbed with: descent 1 comes back to it
        ctx.climb_twist[ctx.number_of_steps] = motion.twist(t.snap)
    return go(P.ASCENT_APPROACH)


def heading_off_rad(t: Tick, twist: float) -> float:
    """How far (radians, + = left) the robot is turned from the heading whose
    odometer twist is ``twist``."""
    return motion.turn_yaw_rad(t.cfg, motion.twist(t.snap) - twist)


def _settled(t: Tick, w: Work) -> bool:
    """Standing still since ``w.still_since`` (set now if unset) for as long
    as the filter takes to stand for here (:func:`settle_s`)."""
    if w.still_since is None:
        w.still_since = t.snap.time_s
    return t.snap.time_s - w.still_since >= settle_s(t.cfg) - 1e-9  # (clocks round alike)


def _measured_standing(t: Tick, w: Work, needed: int) -> bool:
    """True once ``needed`` ticks have been measured; until then, add this
    tick's SFL − SFR to ``w``'s sum when both read a distance.  A reading
    that is an error, a dropout or nothing ahead is no figure for the
    difference: one HC-SR04 dropout (1.3 m) among 25 ticks moved their mean
    by 46 mm, and a robot squared up within 6 mm turned 45 deg away from a
    side wall that was not there (the envelope sweep, case 151 on sonar)."""
    if len(w.diffs) + w.diff_skipped >= needed:
        return True
    r, l_ = motion.pair(t.snap)
    if r.ok and l_.ok and not motion.far(r, t.cfg) and not motion.far(l_, t.cfg):
        w.diffs.append(l_.distance_m - r.distance_m)
        w.standing.append((r.distance_m, l_.distance_m))
    else:
        w.diff_skipped += 1
    return False


TRIM = 0.2
"""The share of the standing ticks' differences left out at each end before
they are averaged."""


def _mean_diff(t: Tick, w: Work) -> float:
    """The mean SFL − SFR measured standing, trimmed of its TRIM highest and
    lowest ticks; now's if no tick gave one.  Two outliers among an HC-SR04's
    last three measurements pass its median and stay for up to three ticks;
    in a plain mean one moved it by centimetres, and a square robot took the
    riser for a side wall (case 2W) and turned 45° away from it (envelope
    cases 71 and 470 on sonar).  Trimmed, the mean of normal noise keeps
    about 90 % of its efficiency."""
    if not w.diffs:
        sfr, sfl = _readings(t)
        return sfl - sfr
    return _trimmed_mean(w.diffs)


def _trimmed_mean(values: list[float]) -> float:
    ordered = sorted(values)
    k = int(len(ordered) * TRIM)
    kept = ordered[k:len(ordered) - k]
    return sum(kept) / len(kept)


# -- check the readings --------------------------------------------------------------
def _check(t: Tick, w: Work) -> Step:
    cfg, ctx = t.cfg, t.ctx
    sfr, sfl = motion.pair(t.snap)
    if ctx.purpose == "descent" and ctx.squaring_turns == 0 and not ctx.turned_back:
        # Descent 1 first turns back to the heading it climbed this step with
        # (by the odometer), so that the way down retraces the way up: squared
        # up within the pair's noise on the way up and again on the way down,
        # the two headings may differ by a few degrees, and over a long flight
        # that put the robot 0.1 m to the side of its start.
        climbed = ctx.climb_twist[t.descent_index]
        if climbed is not None:
            off = heading_off_rad(t, climbed)
            if abs(off) > HEADING_TOLERANCE_RAD:
                ctx.turn_to = climbed
                ctx.turned_back = True  # once a step: then the seed's check
                t.say(f"descent 1, step {t.descent_index + 1}: turned {math.degrees(off):+.2f}° "
                      "from the heading it climbed this step with (by the odometer); turning "
                      "back to it", off_deg=math.degrees(off))
                return go(P.CAL_LIFT)
    # Standing still, the pair is averaged over STILL_TICKS before it is
    # called equal or not: one noisy reading must not choose the case; and
    # only once the filter has settled (a full window of measurements taken
    # standing here: not the first one or two, nor ones taken while moving).
    if not _settled(t, w):
        return stay(NO_MOTION)
    # Checking a squaring turn: as long as it takes to know the difference to
    # within equal_tolerance, as the turn's own check does.
    needed = STILL_TICKS if ctx.squaring_turns == 0 else max(
        STILL_TICKS, still_samples(cfg, min(sfr.distance_m, sfl.distance_m)))
    if not _measured_standing(t, w, needed):
        return stay(NO_MOTION)
    if ctx.squaring_turns > 0:
        return _verify(t, w)
    if motion.far(sfr, cfg) and motion.far(sfl, cfg):
        if ctx.purpose != "start":
            return fail(f"nothing ahead at {where(ctx, P.CAL_CHECK)}: SFR {sfr.distance_m:.3f} m, "
                        f"SFL {sfl.distance_m:.3f} m where a riser should be")
        ctx.calibration_case = "1"
        t.say("calibration case 1: nothing ahead (SFR and SFL read at least "
              f"LENGTH_OF_INFINITY = {cfg.LENGTH_OF_INFINITY} m)", case="1")
        return end("stopped", "nothing ahead: SFR and SFL read at least LENGTH_OF_INFINITY")
    if ctx.purpose == "start":
        if ctx.home_wheel is None:
            ctx.home_wheel = motion.wheel_position(t.snap)
            ctx.home_twist = motion.twist(t.snap)
        near = _nearer(t)
        if near is not None and near > cfg.square_range_m + cfg.algorithm.equal_tolerance:
            t.say(f"calibration (start): SFR {sfr.distance_m:.3f} m, SFL {sfl.distance_m:.3f} m: "
                  f"farther than square_range_m ({cfg.square_range_m:.3f} m), where the front "
                  "cones see over the first riser or the pair's noise allows only a loose "
                  "square; closing in before squaring up",
                  SFR=sfr.distance_m, SFL=sfl.distance_m)
            return go(P.CAL_CLOSE_IN)
    diff = _mean_diff(t, w)
    equal = abs(diff) <= still_tolerance(cfg, max(1, len(w.diffs)),
                                         min(sfr.distance_m, sfl.distance_m))
    if equal and ctx.purpose != "start":
        ctx.calibration_case = None
        return _after_calibration(t)
    # One beam reading nothing ahead is off the flight's open side (a side
    # wall would be seen): the other sees the riser, and case 2's rule turns
    # the right way.  Only two readings that both see something, too far
    # apart for one riser, are a side wall (the envelope sweep: 19 deg askew
    # near the open side of a flight, SFL read nothing, case 2W turned away
    # from the riser until it gave up).
    wall = (not equal and abs(diff) > _one_riser(cfg)
            and not motion.far(sfr, cfg) and not motion.far(sfl, cfg))
    ctx.calibration_case = "3" if equal else ("2W" if wall else "2")
    ctx.case_diff = diff
    said = ("equal, case 3" if equal else
            "too far apart for one riser within "
            f"{math.degrees(MAX_SQUARE_YAW_RAD):.0f}°: the nearer sees a side wall, case 2W"
            if wall else "not equal, case 2")
    t.say(f"calibration ({where(ctx, P.CAL_CHECK)}): SFR {sfr.distance_m:.3f} m, "
          f"SFL {sfl.distance_m:.3f} m: {said}",
          case=ctx.calibration_case, SFR=sfr.distance_m, SFL=sfl.distance_m)
    return go(P.CAL_LIFT)


def _verify(t: Tick, w: Work) -> Step:
    """Check a squaring turn standing on all wheels.  The turn ended on the
    readings taken with segments 1 and 3 lifted, their sensors a clearance
    higher: a cone tilted up then sees more of what lies over a low riser,
    and read equal 17 deg askew on the reference robot (the envelope sweep: the
    standing rule then ended the approach).  Not equal here, the robot turns
    by the odometer as far as the difference says (a flat riser, both beams
    on it), and checks again."""
    ctx, cfg = t.ctx, t.cfg
    r, l_ = motion.pair(t.snap)
    sfr, sfl = r.distance_m, l_.distance_m
    if motion.far(r, cfg) or motion.far(l_, cfg):
        # no figure to square to, nor a riser where it squared up: stop
        return fail(f"calibration ({where(ctx, P.CAL_CHECK)}): squared up, but standing on "
                    f"all wheels SFR reads {sfr:.3f} m and SFL {sfl:.3f} m: at least one sees "
                    "nothing ahead where the riser should be")
    diff = _mean_diff(t, w)
    if abs(diff) <= still_tolerance(cfg, max(1, len(w.diffs)), min(sfr, sfl)):
        t.say(f"square on all wheels: SFL − SFR = {diff * 1000:+.1f} mm over {len(w.diffs)} "
              f"readings standing still (SFR {sfr:.3f} m, SFL {sfl:.3f} m)",
              SFR=sfr, SFL=sfl, diff=diff)
        ctx.squaring_turns = 0
        return _squared(t, w)
    if ctx.squaring_turns >= MAX_SQUARING_TURNS:
        return fail(f"calibration ({where(ctx, P.CAL_CHECK)}) cannot square up: after "
                    f"{ctx.squaring_turns} turns SFL − SFR still reads {diff * 1000:+.1f} mm "
                    f"standing (SFR {sfr:.3f} m, SFL {sfl:.3f} m): the beams do not see one "
                    "flat riser alike (a riser too low for them, or its edge)")
    # SFL farther than SFR: turned left of square, turn right (and the other way).
    yaw = -_askew_rad(cfg, diff)
    yaw = max(-MAX_SQUARE_YAW_RAD, min(MAX_SQUARE_YAW_RAD, yaw))
    ctx.turn_to = motion.twist(t.snap) + motion.yaw_turns(cfg, yaw)
    ctx.squaring_turns += 1
    t.say(f"not square on all wheels: SFL − SFR = {diff * 1000:+.1f} mm over {len(w.diffs)} "
          f"readings standing still (SFR {sfr:.3f} m, SFL {sfl:.3f} m): turning "
          f"{math.degrees(yaw):+.1f}° by the odometer", SFR=sfr, SFL=sfl, diff=diff)
    return go(P.CAL_LIFT)


def _squared(t: Tick, w: Work) -> Step:
    """The calibration is square: the start records where it stands, the
    pair's trimmed means over the ticks the check measured standing still
    (one tick's filtered reading is as noisy as the sensors, and a fault that
    began after the check would count in it whole)."""
    ctx, cfg = t.ctx, t.cfg
    if ctx.purpose == "start":
        if w.standing:
            ctx.start_reading = (_trimmed_mean([r for r, _l in w.standing])
                                 + _trimmed_mean([l_ for _r, l_ in w.standing])) / 2.0
            ctx.start_wheel = motion.wheel_position(t.snap)
            t.say(f"start position: SFR/SFL read {ctx.start_reading:.3f} m (their means "
                  f"over {len(w.standing)} ticks standing still)",
                  start_reading=ctx.start_reading)
        elif motion.measurable(t.snap, cfg):
            ctx.start_reading = motion.mean_distance(t.snap)
            ctx.start_wheel = motion.wheel_position(t.snap)
            t.say(f"start position: SFR/SFL read {ctx.start_reading:.3f} m",
                  start_reading=ctx.start_reading)
        if t.mode is Mode.CALIBRATE_ONLY:
            return end("completed", "calibrate-only: calibration done")
    return _after_calibration(t)


def _askew_rad(cfg: RobotConfig, diff: float) -> float:
    """How far the robot is turned left of square (radians) when both beams
    on one flat riser read SFL − SFR = ``diff``."""
    return math.atan(diff / (2 * max(cfg.sensors.front_lateral, 1e-6)))


def _one_riser(cfg: RobotConfig) -> float:
    """The largest SFL − SFR (either sign) both beams on one riser can read,
    the robot turned MAX_SQUARE_YAW_RAD from square to it."""
    return 2 * cfg.sensors.front_lateral * math.tan(MAX_SQUARE_YAW_RAD)


def _nearer(t: Tick) -> float | None:
    """The nearer of SFR and SFL that reads a distance (None: neither)."""
    seen = [r.distance_m for r in motion.pair(t.snap) if r.ok and not motion.far(r, t.cfg)]
    return min(seen, default=None)


CHECK = PhaseDef(
    P.CAL_CHECK, "calibration — check the readings (case 1?)", FLOW, _check,
    to={
        P.DONE: "case 1: both read ≥ LENGTH_OF_INFINITY (nothing ahead); calibrate-only: "
                "squared up (checked)",
        P.CAL_CLOSE_IN: "start: the nearer reads farther than square_range_m",
        P.CAL_LIFT: "start: case 2 (SFR ≠ SFL), 2W (too far apart for one riser) or case 3 "
                    "(SFR = SFL); later: SFR ≠ SFL; descent 1: turned from the heading the "
                    "step was climbed with; a squaring turn checked and not square: correct it",
        P.ASCENT_APPROACH: "ascent 1 on a later step: SFR = SFL; or squared up (checked)",
        P.DESCENT_BACK_TO_EDGE: "descent 1: SFR = SFL; or squared up (checked)",
        P.ERROR: "case 1: sensor error; later: nothing ahead where a riser should be; "
                 "checking a squaring turn: nothing ahead, or still not square after "
                 "MAX_SQUARING_TURNS turns",
    })


# -- close in (start) -------------------------------------------------------------------
def _close_in_enter(t: Tick, w: Work) -> None:
    # No further than the first reading allows: its nearer beam to square_range_m.
    near = _nearer(t)
    assert near is not None  # CAL_CHECK closes in only on a reading
    w.target_wheel = w.entry_wheel + t.cfg.wheel_turns(near - t.cfg.square_range_m)


def _close_in(t: Tick, w: Work) -> Step:
    """Drive straight on, not squared up (the standing rule is not armed), until
    the nearer beam reads square_range_m or the first reading's distance is
    driven; then check the readings again, standing still."""
    assert w.target_wheel is not None  # set on entry
    near = _nearer(t)
    remaining = w.target_wheel - motion.wheel_position(t.snap)
    if remaining <= motion.WHEEL_DONE or (near is not None and near <= t.cfg.square_range_m):
        return go(P.CAL_CHECK, f"closed in: SFR/SFL nearer reads "
                               f"{'nothing' if near is None else f'{near:.3f} m'}")
    return stay(motion.drive(t.cfg, 1, remaining))


CLOSE_IN = PhaseDef(
    P.CAL_CLOSE_IN, "calibration — close in to square_range_m (start)", FLOW, _close_in,
    enter=_close_in_enter,
    to={P.CAL_CHECK: "the nearer reads square_range_m, or the first reading's distance driven",
        P.ERROR: FAULT})


# -- lift segments 1 and 3 for clearance -----------------------------------------------
def _lift_deltas(t: Tick, w: Work) -> dict[MotorId, float]:
    ctx, cfg = t.ctx, t.cfg
    ctx.return_mtf, ctx.return_mtb = w.entry_mtf, w.entry_mtb
    up = cfg.NUMBER_OF_VERTICAL_TURNS_FOR_CLEARANCE
    limit = cfg.MAX_OF_VERTICAL_TURNS
    return {MotorId.MTF: min(up, limit - w.entry_mtf), MotorId.MTB: min(up, limit - w.entry_mtb)}


def _lifted(t: Tick, _w: Work) -> Step:
    if t.ctx.squaring_turns == 0:
        # a calibration's first turn; its corrections count towards the same
        # MAX_TURN_YAW_RAD
        t.ctx.turn_origin = t.snap.turns(MotorId.MWR)
    if t.ctx.turn_to is not None:
        return go(P.CAL_TURN_TO)
    case = t.ctx.calibration_case
    return go(P.CAL_TURN if case == "2" else P.CAL_AWAY if case == "2W" else P.CAL_PROBE)


_lift_enter, _lift_step = lift(_lift_deltas, _lifted)
LIFT = PhaseDef(
    P.CAL_LIFT, "calibration — lift segments 1 and 3 for clearance", FLOW, _lift_step,
    enter=_lift_enter, carried_by=(2,),
    to={P.CAL_TURN: "lifted; case 2", P.CAL_AWAY: "lifted; case 2W",
        P.CAL_PROBE: "lifted; case 3",
        P.CAL_TURN_TO: "lifted; a correction of the squaring turn, or descent 1 or 7 "
                       "turning back to a heading it had",
        P.ERROR: FAULT})


# -- turning ---------------------------------------------------------------------------
def _turned_too_far(t: Tick, phase: Phase) -> Step | None:
    made = abs(t.snap.turns(MotorId.MWR) - t.ctx.turn_origin)
    if motion.turn_yaw_rad(t.cfg, made) <= MAX_TURN_YAW_RAD:
        return None
    return fail(f"calibration ({where(t.ctx, phase)}) turned "
                f"{math.degrees(MAX_TURN_YAW_RAD):.0f}° without finding SFR = SFL")


def _turn_enter(t: Tick, w: Work) -> None:
    r, l_ = motion.pair(t.snap)
    sfr, sfl = r.distance_m, l_.distance_m
    # SFL < SFR: the left side is nearer, turn left (the seed's case 2 rule).
    w.turn_direction = 1 if sfl < sfr else -1
    w.turn_diff = sfl - sfr
    # Both beams on one riser, the difference says how far the robot is turned
    # from square to it: the turn may make that and a margin, no more.
    w.turn_from = t.snap.turns(MotorId.MWR)
    if motion.far(r, t.cfg) or motion.far(l_, t.cfg):
        # one beam off the flight's side: no figure, at most as askew as a
        # calibration may stand
        w.turn_limit_rad = MAX_SQUARE_YAW_RAD + TURN_MARGIN_RAD
    else:
        # the larger of what the standing mean the case was chosen on says and
        # what the readings now say: one tick of a Sharp pair 0.36 m away read
        # 1 deg askew where the mean had said 16 (ir envelope case 1452)
        diff = max(abs(sfl - sfr), abs(t.ctx.case_diff or 0.0))
        w.turn_limit_rad = _askew_rad(t.cfg, diff) + TURN_MARGIN_RAD


def _turned_past_limit(t: Tick, w: Work) -> Step | None:
    made = motion.turn_yaw_rad(t.cfg, abs(t.snap.turns(MotorId.MWR) - w.turn_from))
    if made <= w.turn_limit_rad:
        return None
    return fail(f"calibration ({where(t.ctx, P.CAL_TURN)}) turned {math.degrees(made):.0f}° "
                f"without finding SFR = SFL, more than the "
                f"{math.degrees(w.turn_limit_rad):.0f}° its first readings allow: "
                "not squaring up to something other than the riser")


def _turn(t: Tick, w: Work) -> Step:
    cfg = t.cfg
    sfr, sfl = _readings(t)
    if w.checked:  # stopped at SFR = SFL: measuring standing still, once settled
        if not _settled(t, w):
            return stay(NO_MOTION)
        # as long as it takes to know the difference to within equal_tolerance
        if not _measured_standing(t, w, max(STILL_TICKS, still_samples(cfg, min(sfr, sfl)))):
            return stay(NO_MOTION)
        diff = _mean_diff(t, w)
        if abs(diff) <= still_tolerance(cfg, max(1, len(w.diffs)), min(sfr, sfl)):
            t.say(f"squared up: SFL − SFR = {diff * 1000:+.1f} mm over {len(w.diffs)} readings "
                  f"standing still (SFR {sfr:.3f} m, SFL {sfl:.3f} m)", SFR=sfr, SFL=sfl,
                  diff=diff)
            t.ctx.squaring_turns += 1
            return go(P.CAL_LOWER)
        # Not square yet: turn on, slowly, the way the difference says.
        direction = 1 if diff < 0 else -1  # as on entry: SFL nearer, turn left
        if direction != w.turn_direction:
            w.turn_flips += 1
            if w.turn_flips > MAX_TURN_FLIPS:
                return fail(f"calibration ({where(t.ctx, P.CAL_TURN)}) turned back and forth "
                            f"{MAX_TURN_FLIPS} times without finding SFR = SFL: standing, "
                            f"SFL − SFR reads {diff * 1000:+.1f} mm (SFR {sfr:.3f} m, SFL "
                            f"{sfl:.3f} m); a beam may be off the flight's side, or one "
                            "sensor reading long or short")
        w.checked, w.diffs, w.diff_skipped, w.still_since = False, [], 0, None
        w.turn_direction = direction
        w.turn_diff = diff
    w.turn_diff = motion.smooth(w.turn_diff, sfl - sfr)
    # Turning left closes SFL - SFR from below, turning right from above: stop
    # when the smoothed difference has reached zero (or, with readings that
    # no longer change, has decayed to a twentieth of their resolution), then
    # check it standing still.
    remaining = -w.turn_direction * w.turn_diff
    if remaining <= cfg.sensors.resolution / 20:
        w.checked = True
        return stay(NO_MOTION)
    too_far = _turned_too_far(t, P.CAL_TURN) or _turned_past_limit(t, w)
    if too_far is not None:
        return too_far
    slow = min(1.0, max(TURN_SLOW_FLOOR, remaining / (2 * cfg.algorithm.equal_tolerance)))
    return stay(motion.turn(w.turn_direction, cfg, slow))


TURN = PhaseDef(
    P.CAL_TURN, "calibration case 2 — turn until SFR = SFL", FLOW, _turn, enter=_turn_enter,
    to={P.CAL_LOWER: "SFR = SFL",
        P.ERROR: "turned too far, or more than its first readings allow; " + FAULT})


def _probe_enter(t: Tick, w: Work) -> None:
    w.probe_sfr, w.probe_sfl = _readings(t)


def _probe(t: Tick, w: Work) -> Step:
    """Lifted, measure SFR and SFL standing still, then turn left and watch
    how they change.  Both ends of the comparison are means: the start the
    trimmed mean standing, now the mean of the last PROBE_TICKS ticks.  One
    tick at each end let a square VL53L1X pair's noise look like a corner
    ("SFR grew 12 mm, SFL shrank 4 mm" against a start reading 13 mm long):
    case 3B turned 42 deg looking for the riser and the robot was stranded
    (the envelope sweep, cases 1119 and 1967 on reference)."""
    ctx, cfg = t.ctx, t.cfg
    if not w.checked:
        if not _settled(t, w) or not _measured_standing(t, w, STILL_TICKS):
            return stay(NO_MOTION)
        if not w.standing:  # no tick gave both: now's readings, as the seed
            w.standing.append(_readings(t))
        w.probe_sfr = _trimmed_mean([r for r, _l in w.standing])
        w.probe_sfl = _trimmed_mean([l_ for _r, l_ in w.standing])
        w.checked = True
    r, l_ = motion.pair(t.snap)
    both = r.ok and l_.ok and not motion.far(r, cfg) and not motion.far(l_, cfg)
    if both:
        w.probe_recent = [*w.probe_recent[-(PROBE_TICKS - 1):], (r.distance_m, l_.distance_m)]
        sfr = sum(r_ for r_, _l in w.probe_recent) / len(w.probe_recent)
        sfl = sum(l_ for _r, l_ in w.probe_recent) / len(w.probe_recent)
    else:
        # A beam off the riser (or past LENGTH_OF_INFINITY) is as large a
        # change as there is: now's readings.  Waiting for five ticks that
        # see something, an ideal robot 18 deg askew 0.97 m away turned on
        # until both beams read nothing, and squared up to nothing (the
        # envelope sweep, case 1004 on ideal).
        sfr, sfl = _readings(t)
    # a corner is decided on a full window of means only
    window_full = both and len(w.probe_recent) >= PROBE_TICKS
    made = abs(t.snap.turns(MotorId.MWR) - ctx.turn_origin)
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
    ctx.calibration_case = "3B" if corner else "3A"
    data = {"case": ctx.calibration_case, "dSFR": d_sfr, "dSFL": d_sfl}
    if corner:
        t.say(f"calibration case 3B: a corner (turning left, SFR grew {d_sfr * 1000:.1f} mm, "
              f"SFL shrank {-d_sfl * 1000:.1f} mm); turning on until both shrink", **data)
        return go(P.CAL_CORNER)
    t.say(f"calibration case 3A: square to the riser (turning left, SFR changed "
          f"{d_sfr * 1000:+.1f} mm, SFL {d_sfl * 1000:+.1f} mm); turning back", **data)
    return go(P.CAL_TURN)


PROBE = PhaseDef(
    P.CAL_PROBE, "calibration case 3 — probe turn left (A or B?)", FLOW, _probe,
    to={P.CAL_CORNER: "SFR grew, SFL shrank: case 3B",
        P.CAL_TURN: "otherwise: case 3A, turn back right", P.ERROR: FAULT})


def _corner(t: Tick, w: Work) -> Step:
    sfr, _sfl = _readings(t)
    w.probe_sfr = max(w.probe_sfr, sfr)  # the largest SFR seen while turning
    if sfr < w.probe_sfr - t.cfg.algorithm.equal_tolerance:
        t.say(f"case 3B: SFR shrinks again ({sfr:.3f} m): both see the riser")
        return go(P.CAL_TURN)
    too_far = _turned_too_far(t, P.CAL_CORNER)
    if too_far is not None:
        return too_far
    return stay(motion.turn(1, t.cfg))


CORNER = PhaseDef(
    P.CAL_CORNER, "calibration case 3B — turn left until both readings shrink", FLOW, _corner,
    enter=_probe_enter,
    to={P.CAL_TURN: "both readings shrink", P.ERROR: "turned too far; " + FAULT})


def _away_enter(t: Tick, w: Work) -> None:
    sfr, sfl = _readings(t)
    # The nearer beam sees a side wall: turn away from it (left when SFR is
    # the nearer), the opposite of case 2's rule, until it sees the riser.
    w.turn_direction = 1 if sfr < sfl else -1
    w.turn_diff = sfl - sfr
    w.turn_from = t.snap.turns(MotorId.MWR)


def _away(t: Tick, w: Work) -> Step:
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
    w.checked = w.checked or flipped
    off_wall = flipped and abs(d) >= cfg.algorithm.equal_tolerance
    passed_square = w.checked and not flipped and abs(d) <= _one_riser(cfg)
    if seen and (off_wall or passed_square):
        t.say(f"case 2W: off the side wall, SFR {sfr:.3f} m and SFL {sfl:.3f} m see the "
              "riser; squaring up", SFR=sfr, SFL=sfl)
        return go(P.CAL_TURN)
    made = motion.turn_yaw_rad(cfg, abs(t.snap.turns(MotorId.MWR) - w.turn_from))
    if made > MAX_AWAY_YAW_RAD:
        return fail(f"calibration ({where(t.ctx, P.CAL_AWAY)}) turned "
                    f"{math.degrees(MAX_AWAY_YAW_RAD):.0f}° away from the side wall and the "
                    f"readings still do not fit one riser (SFR {sfr:.3f} m, SFL {sfl:.3f} m)")
    return stay(motion.turn(w.turn_direction, cfg))


AWAY = PhaseDef(
    P.CAL_AWAY, "calibration case 2W — turn away from the side wall until both see the riser",
    FLOW, _away, enter=_away_enter,
    to={P.CAL_TURN: "off the wall: the pair flipped (or flipped back, square)",
        P.ERROR: "turned too far; " + FAULT})


# -- turn back to a heading (descent 1 and 7) ------------------------------------------
def _turn_to(t: Tick, w: Work) -> Step:
    """Turn on segment 2's wheels until the odometer's heading is ctx.turn_to."""
    assert t.ctx.turn_to is not None  # set by whoever lifted for this turn
    remaining = t.ctx.turn_to - motion.twist(t.snap)
    if abs(remaining) <= motion.WHEEL_DONE:
        return go(P.CAL_LOWER)
    too_far = _turned_too_far(t, P.CAL_TURN_TO)
    if too_far is not None:
        return too_far
    slow = min(1.0, max(TURN_SLOW_FLOOR, abs(remaining) / motion.WHEEL_SLOW_ZONE))
    return stay(motion.turn(1 if remaining > 0 else -1, t.cfg, slow))


TURN_TO = PhaseDef(
    P.CAL_TURN_TO, "calibration — turn by the odometer to a heading", FLOW,
    _turn_to,
    to={P.CAL_LOWER: "turned to it", P.ERROR: "turned too far; " + FAULT})


# -- lower segments 1 and 3 --------------------------------------------------------------
def _lower_deltas(t: Tick, w: Work) -> dict[MotorId, float]:
    ctx = t.ctx
    return {MotorId.MTF: ctx.return_mtf - w.entry_mtf, MotorId.MTB: ctx.return_mtb - w.entry_mtb}


def _lowered(t: Tick, _w: Work) -> Step:
    ctx = t.ctx
    ctx.turn_to = None
    if ctx.purpose == "home":
        return go(P.DESCENT_FINISH_FLOOR)
    if ctx.purpose == "floor":
        return go(P.DESCENT_FINISH)
    # Check standing on all wheels, once the filter has settled there (the
    # check waits for it): a squaring turn (squaring_turns > 0), or descent
    # 1's turn back to the climb's heading (the seed's check).  Segment 1
    # settling onto its wheels pitches the beams down for a moment, and a
    # cone then reads the floor (the reference robot took its start reading there,
    # 0.202 m for 0.327 m, and came home 0.125 m short).
    return go(P.CAL_CHECK)


_lower_enter, _lower_step = lift(_lower_deltas, _lowered)
LOWER = PhaseDef(
    P.CAL_LOWER, "calibration — lower segments 1 and 3", FLOW, _lower_step, enter=_lower_enter,
    carried_by=(2,),
    to={P.CAL_CHECK: "lowered: check standing on all wheels",
        P.DESCENT_FINISH_FLOOR: "lowered (descent 7, turned back to where the program began)",
        P.DESCENT_FINISH: "lowered (descent 7, turned back to the floor's heading)",
        P.ERROR: FAULT})

PHASES: tuple[PhaseDef, ...] = (CHECK, CLOSE_IN, LIFT, PROBE, CORNER, AWAY, TURN, TURN_TO, LOWER)
