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

from stairbot.algorithm import motion
from stairbot.algorithm.ascent import narrow
from stairbot.algorithm.calibration import HEADING_TOLERANCE_RAD, heading_off_rad
from stairbot.algorithm.moves import (
    checked_first,
    drive_phase,
    lift,
    lift_phase,
    reading_drive,
    turns_drive,
)
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
from stairbot.algorithm.phases import Phase
from stairbot.algorithm.work import Work
from stairbot.config import RobotConfig
from stairbot.hardware import BACK_SENSORS, WHEEL_MOTORS, MotorId, SensorStatus
from stairbot.perception import measurement_period, median_sigma, window

P = Phase
FLOW = "descent"


def _tab(t: Tick) -> float | None:
    return t.ctx.tab_length_to_edge[t.descent_index]


def _h(t: Tick) -> float:
    return t.ctx.number_of_turns_for_step_height


def _narrow(t: Tick, index: int | None = None) -> bool:
    """The tread of step ``index`` (default: the one being descended, which
    the robot stands on) is narrow: the robot does not fit on it, and its
    segment 3 hangs in the air over the step below (narrow_steps)."""
    i = t.descent_index if index is None else index
    return not t.ctx.from_top and 0 <= i and narrow(t.cfg, t.ctx.tread_length[i])


# -- descent 1: back off, calibrate, back up to the edge ---------------------------------------
def _backed_off(t: Tick, w: Work) -> Step:
    t.ctx.purpose = "descent"
    if w.edge_stop is not None:
        return fail(w.edge_stop)
    if w.square_yaw is not None:
        return _turn_square(t, w)
    if t.ctx.from_top:
        # squared up to the edge by the back pair instead (a riser too low for
        # the front cone read as nothing ahead, and ended the program)
        return go(P.DESCENT_BACK_TO_EDGE)
    return go(P.CAL_CHECK)


def _back_off_enter(t: Tick, w: Work) -> None:
    t.ctx.edge_wheel = None  # a new step: its edge not seen yet, nor turned back
    t.ctx.turned_back = t.ctx.edge_squared = False
    _back_off_drive[0](t, w)


def _back_off_target(t: Tick) -> float | None:
    """None (the seed's turns), or, on a narrow step, tab_length_to_edge: the
    robot does not fit on the tread, and backing off the seed's approach
    turns would take segment 2's wheels over the edge.  Its segment 3 hangs
    over the step below already; where segment 2's rear wheels stand on the
    edge is where ascent 7 read the tab."""
    return _tab(t) if _narrow(t) else None


def _edge_or_tab(t: Tick, w: Work, refind: bool) -> float | None:
    """The edge watch's bound (:func:`_edge_bound`); on a narrow step, the
    tab read on the way up places the robot (the back pair is over the step
    below, segment 3 in the air), bounded by :func:`_narrow_bound`."""
    if not _narrow(t):
        return _edge_bound(t, w, refind)
    limit = _narrow_bound(t, w, t.descent_index)
    if limit is None or w.target_wheel is None:
        return limit
    # a limit, not where the drive ends (backing up to the edge is exact to its bound)
    return max(limit, w.target_wheel)


NARROW_AXLE_MARGIN_M = 0.004
"""On a narrow step, descent 1 never backs segment 2's rear axle nearer the
edge than this (the tab puts it 8.5 mm past it, as ascent 6 left it)."""


def _narrow_bound(t: Tick, w: Work, index: int) -> float | None:
    """Narrow steps: watch the back pair cross the edge of the narrow tread
    of step ``index`` (floor, then the drop, as :func:`_edge_bound` does) and
    keep where (``Context.narrow_edge_wheel``); once known, the odometer
    count the backing never passes: segment 2's rear axle
    NARROW_AXLE_MARGIN_M past that edge.  The front pair alone placed the
    robot there, with 8.5 mm to spare: both of its sensors reading 20 mm
    short (a common fault the standing rule cannot see) backed segment 2's
    rear wheels off the edge, and the robot fell (the narrow steps' red
    team)."""
    cfg, ctx = t.cfg, t.ctx
    if not _narrow(t, index):
        return None
    if ctx.narrow_edge_wheel is None:
        if not _sees_drop(t):
            w.edge_floor_s = t.snap.time_s
        elif w.edge_floor_s is not None:
            speed = sum(t.snap.motors[m].speed_tps for m in WHEEL_MOTORS) / len(WHEEL_MOTORS)
            sight = edge_sight_m(cfg, speed * cfg.wheel_circumference)
            ctx.narrow_edge_wheel = motion.wheel_position(t.snap) + cfg.wheel_turns(sight)
    if ctx.narrow_edge_wheel is None:
        return None
    g = cfg.geometry
    reach = g.LENGTH_OF_THIRD_MODULE - cfg.sensors.back_from_rear + g.wheel_inset
    return ctx.narrow_edge_wheel - cfg.wheel_turns(reach - NARROW_AXLE_MARGIN_M)


def _narrow_tab_known(t: Tick, _w: Work) -> Step | None:
    if _narrow(t) and _tab(t) is None:
        return fail(f"descent 1: tab_length_to_edge[{t.descent_index}] was not measured on "
                    "a narrow step: the robot cannot be placed on a tread it does not fit on")
    return None


def _back_off_turns(t: Tick) -> float:
    """The seed's approach turns; on a narrow step, while the front pair
    cannot read (descent 6 left it nearer the riser than it reads from),
    the tab less the approach's gap, where descent 5 left segment 1's front
    face: the seed's turns (0.1 m) took segment 2's rear wheels over the
    edge, and the robot tipped back (the narrow sweep, case 16: +129 deg/s)."""
    tab = _tab(t)
    if _narrow(t) and tab is not None:
        return t.cfg.wheel_turns(max(0.0, tab - t.cfg.algorithm.approach_gap))
    return t.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH


_back_off_drive = reading_drive(-1, _back_off_target, _back_off_turns,
                                _backed_off, lambda t, w: _edge_or_tab(t, w, refind=False))
BACK_OFF = PhaseDef(
    P.DESCENT_BACK_OFF, "descent 1 — back off to a safe position", FLOW,
    checked_first(_narrow_tab_known, _back_off_drive[1]),
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


def _edge_known(t: Tick, _w: Work) -> Step | None:
    if _tab(t) is None and not t.ctx.from_top:
        return fail(f"descent 1: tab_length_to_edge[{t.descent_index}] was not measured; "
                    "the edge of the step cannot be found")
    return None


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


def _edge_fallback(t: Tick) -> float:
    if t.ctx.from_top:
        return t.cfg.wheel_turns(edge_search_m(t))
    # Descent 1 backed off to SAFE_DISTANCE_IN_FRONT_OF_STEP before calibrating.
    tab = _tab(t) or t.cfg.SAFE_DISTANCE_IN_FRONT_OF_STEP
    return t.cfg.wheel_turns(max(0.0, tab - t.cfg.SAFE_DISTANCE_IN_FRONT_OF_STEP))


EDGE_MARGIN_M = 0.006
"""Segment 3's front wheels stop this far clear of the edge's corner."""


def edge_clearance_m(cfg: RobotConfig) -> float:
    """How far the robot backs after its back pair (``back_from_rear`` from
    segment 3's rear) crossed the edge until segment 3's front wheels are
    clear of it, their front EDGE_MARGIN_M past its corner: over the step
    below, and not yet so far that the robot tips back off segment 2's rear
    wheels.  (Their centre a wheel radius past it, the wheels stood on the
    corner: lowered, segment 3 stayed up and the lift pitched segment 2 12
    deg nose down -- the envelope sweep on the sonar robot, once the edge
    was placed where the pair crossed it.)"""
    g = cfg.geometry
    return (g.LENGTH_OF_THIRD_MODULE - cfg.sensors.back_from_rear - g.wheel_inset
            + g.wheel_radius + EDGE_MARGIN_M + edge_doubt_m(cfg))


def edge_doubt_m(cfg: RobotConfig) -> float:
    """How far off :func:`edge_sight_m` may place the crossing: the distance
    backed at full speed in one of the back pair's measurement periods (the
    crossing falls anywhere between two measurements, and the median's
    majority may take one more).  Added to the clearance: an HC-SR04 pair,
    measuring every 60 ms, placed segment 3's front wheels up to 10 mm short
    of where it meant to, on the corner, and lowered there, segment 3 pitched
    the robot 15 deg nose down (the envelope sweep, cases 1631 and 1636 on
    sonar)."""
    return cfg.wheel_speed_m_s * measurement_period(cfg, True)


LOW_DROP_M = 0.015
"""A continuous descent takes a drop this much past BACK_CLEARANCE (and its
noise) for an edge: it has not climbed the flight, and a rise lower than
half min_step_rise_m, unseen, was backed off wheels first (the red team:
0.03-0.065 m rises tipped the robot back; 0.015 m is under a 32 mm wheel's
radius)."""


def edge_drop_m(cfg: RobotConfig, from_top: bool = False) -> float:
    """The back pair reads "past the edge" beyond this: more than half the
    lowest rise below BACK_CLEARANCE (and its noise); in a continuous
    descent, LOW_DROP_M more than BACK_CLEARANCE (and its noise)."""
    low = LOW_DROP_M if from_top else cfg.min_step_rise_m / 2
    return cfg.BACK_CLEARANCE + floor_tolerance(cfg) + low


def edge_lag_s(cfg: RobotConfig) -> float:
    """How long after the back pair crosses an edge perception reports the
    drop: the sensor's latency, then the median's majority of the window,
    one period each, the first of them half a period after the crossing on
    average."""
    return cfg.sensors.spec(True).latency_s \
        + (window(cfg, True) // 2 + 0.5) * measurement_period(cfg, True)


def edge_sight_m(cfg: RobotConfig, speed_mps: float, from_top: bool = False) -> float:
    """How far past an edge the back pair's sensors are when perception first
    reports the drop, backing at ``speed_mps``: the distance backed while
    the measurements came through (the sensor's latency, then the median's
    majority of the window, one period each, the first of them half a
    period after the crossing on average), and for a sensor that reports
    the first echo in its cone, the riser's face below the edge that the
    cone's back half keeps seeing, nearer than the drop, until the sensor
    is ``edge_drop_m`` x sin(half the cone) past it.  The HC-SR04 pair saw
    the drop 2.4 cm past the edge; backing edge_clearance_m from there, the
    sonar robot tipped back (the envelope sweep, case 925)."""
    spec = cfg.sensors.spec(True)
    sight = abs(speed_mps) * edge_lag_s(cfg)
    if spec.first_echo:
        fov = spec.fov_deg if cfg.sensors.back_fov_deg is None else cfg.sensors.back_fov_deg
        sight += edge_drop_m(cfg, from_top) * math.sin(math.radians(fov) / 2)
    return sight


EDGE_GAP_TICKS = 2.5
"""The edge watch missed a stretch when two of its ticks are further apart
than this many control ticks."""
REFIND_TICKS = 3
"""Finding the floor again: ticks in a row the back pair must read it."""


def _drops(t: Tick) -> list[bool]:
    """Each of SBR and SBL reads past an edge: more than edge_drop_m, or
    nothing in range."""
    cfg, drop = t.cfg, edge_drop_m(t.cfg, t.ctx.from_top)
    return [r.status is SensorStatus.OUT_OF_RANGE and r.distance_m > cfg.BACK_CLEARANCE
            or r.ok and r.distance_m > drop
            for r in (t.snap.sensors[s] for s in BACK_SENSORS)]


def _sees_drop(t: Tick) -> bool:
    """The back pair reads past an edge: both of them."""
    return all(_drops(t))


EDGE_SQUARE_RAD = math.radians(3.0)
"""Continuous descent: turned further than this from square to the edge (by
how far it backed between SBR and SBL reading the drop), the robot turns
square before it backs on.  Set down 13 deg askew, it placed the edge where
the second sensor crossed, backed the clearance, and segment 2's wheels on
the first one's side went over (the red team: +15.5 deg, then a fall);
the estimate's own error is about one measurement period's backing across
the pair's spacing (3 deg for an HC-SR04 pair)."""
MAX_EDGE_YAW_RAD = math.radians(25.0)
"""One back sensor reads the drop and the other still the floor after the
robot backed as far as this yaw across the pair's spacing: it stops."""


def _square_to_edge(t: Tick, w: Work) -> str | None:
    """Continuous descent: watch which back sensor reads the drop first; once
    both do, the yaw to square up (``w.square_yaw``), if more than
    EDGE_SQUARE_RAD and not squared at this edge yet; an error if the other
    does not follow within MAX_EDGE_YAW_RAD.  Only on a crossing the watch
    sees as it happens (``w.edge_floor_s``).  Returns the error that ends
    the program, if any."""
    ctx, cfg = t.ctx, t.cfg
    if not ctx.from_top or ctx.edge_wheel is not None or w.edge_floor_s is None:
        return None
    right, left = _drops(t)
    here = motion.wheel_position(t.snap)
    if not right and not left:
        w.edge_first_wheel = w.edge_first = None  # both on the floor: no crossing begun
        return None
    if right != left:
        first = "SBR" if right else "SBL"
        if w.edge_first_wheel is None or w.edge_first != first:
            w.edge_first_wheel, w.edge_first = here, first
        lag = (w.edge_first_wheel - here) * cfg.wheel_circumference
        most = 2 * cfg.sensors.back_lateral * math.tan(MAX_EDGE_YAW_RAD)
        if lag > most:
            other = "SBL" if right else "SBR"
            return (f"descent 1: {first} reads the drop, {other} still the floor "
                        f"after backing {lag * 1000:.0f} mm more (at most {most * 1000:.0f} mm: "
                        f"{math.degrees(MAX_EDGE_YAW_RAD):.0f}° from square to the edge): "
                        "turned too far from the edge, or the edge is not straight")
        return None
    if right and w.edge_first_wheel is not None and not ctx.edge_squared:
        lag = (w.edge_first_wheel - here) * cfg.wheel_circumference
        yaw = math.atan2(lag, 2 * cfg.sensors.back_lateral)
        if yaw > EDGE_SQUARE_RAD:
            # SBR first: its side is further back, the robot turned right: turn left
            w.square_yaw = yaw if w.edge_first == "SBR" else -yaw
            t.say(f"{w.edge_first} read the drop {lag * 1000:.0f} mm before the other: "
                  f"{math.degrees(yaw):.1f}° from square to the edge; turning "
                  f"{'left' if w.square_yaw > 0 else 'right'} to square up",
                  edge_yaw_deg=math.degrees(w.square_yaw))
    return None


def _edge_bound(t: Tick, w: Work, refind: bool) -> float | None:
    """Descent 1's backing (backing off, and backing up to the edge) never
    passes edge_clearance_m beyond where the back pair saw the drop (more
    than half the lowest rise below BACK_CLEARANCE, or nothing in range):
    tab_length_to_edge, read on the way up, may be a centimetre or two off,
    and the robot tipped back where it was; and on a tread little longer
    than the robot, backing off the seed's approach turns already takes
    segment 3 past the edge (the envelope sweep: the reference robot tipped back
    backing up to the edge after that).

    Where the pair crossed is worked out only from a crossing the watch saw
    as it happened: the pair read the floor on a tick of this phase, then
    the drop, with no stretch between missed.  Otherwise -- the pair already
    past the edge when the phase began (it crossed as the back-off ended,
    or while calibration turned), or a tick came late (a stalled host: the
    robot ran on unwatched) -- where it crossed is not known: the back-off
    ends where it is, and backing up to the edge first drives forward until
    the pair reads the floor again (``refind``: :func:`_refind`).  Placed
    at the tick that saw the drop, with the robot standing, the crossing
    was put 0 mm behind the pair, and backing the whole clearance from
    there tipped the robot back (``benchmarks/soak_host_stalls.py``, seed 19:
    +15.8 deg)."""
    cfg, ctx = t.cfg, t.ctx
    if ctx.edge_wheel is None:
        now = t.snap.time_s
        if w.square_yaw is None and w.edge_stop is None:
            w.edge_stop = _square_to_edge(t, w)
        if w.edge_stop is not None or w.square_yaw is not None:
            # the step wrapper ends the program, or turns square first (the
            # back-off ends here and turns)
            return None if refind else motion.wheel_position(t.snap)
        if w.edge_watch_s is not None \
                and now - w.edge_watch_s > EDGE_GAP_TICKS * cfg.algorithm.tick:
            # a stretch unwatched: the floor read before it no longer counts,
            # nor one read until perception's lag has passed
            w.edge_floor_s = None
            w.edge_blind_until = now + edge_lag_s(cfg) + measurement_period(cfg, True)
        w.edge_watch_s = now
        if not _sees_drop(t):
            if w.edge_blind_until is None or now > w.edge_blind_until:
                w.edge_floor_s = now
        elif w.edge_floor_s is None:
            if refind:
                w.refind_from = motion.wheel_position(t.snap)
                w.refind_floor = 0
                t.say("SBR/SBL read past the edge, but they were not seen crossing it: "
                      "driving forward until they read the floor again")
                return None
            return motion.wheel_position(t.snap)  # the back-off ends here
        else:
            speed = sum(t.snap.motors[m].speed_tps for m in WHEEL_MOTORS) / len(WHEEL_MOTORS)
            sight = edge_sight_m(cfg, speed * cfg.wheel_circumference, ctx.from_top)
            # where they crossed it: behind the robot's back (backing, the
            # odometer runs down), so the crossing was at a larger count
            ctx.edge_wheel = motion.wheel_position(t.snap) + cfg.wheel_turns(sight)
            more = max(0.0, edge_clearance_m(cfg) - sight)
            t.say(f"SBR/SBL see the edge (read {motion.mean_distance(t.snap, back=True):.3f} m, "
                  f"about {sight * 1000:.0f} mm past it): backing at most {more:.3f} m more")
    if ctx.edge_wheel is None:
        return None
    return ctx.edge_wheel - cfg.wheel_turns(edge_clearance_m(cfg))


# Once the back pair has crossed the edge, the backing ends edge_clearance_m
# past it, wherever tab_length_to_edge would stop it: read on the way up
# where segment 3 was lifted over the edge, it left segment 3's front wheels
# on the edge's corner, and lowered, segment 3 stayed up while the lift
# pitched the robot (the envelope sweep, case 781 on ir).
def _at_edge(t: Tick, w: Work) -> Step:
    """Backed up to the edge.  In a continuous descent, backing the whole
    search without seeing an edge is the floor.  (Its tab_length_to_edge stay
    unknown, and descent 3 and 5 go by the seed's turn counts: the front pair
    looks back up at risers the robot did not climb, and a cone sees over a
    low one as the robot backs away from it -- the descent sweep: on 0.08 m
    risers SFR/SFL jumped 70 mm to the riser beyond, descent 5 ended at once,
    and segment 1, lowered on the edge, pitched the robot 15 deg nose up.)"""
    ctx = t.ctx
    if not ctx.from_top or ctx.edge_wheel is not None:
        return go(P.DESCENT_LOWER_THIRD)
    searched = (w.entry_wheel - motion.wheel_position(t.snap)) * t.cfg.wheel_circumference
    if ctx.steps_descended == 0:
        return end("stopped", f"no edge behind: SBR/SBL read the floor for {searched:.2f} m "
                              f"backing from the start (at most LENGTH_OF_INFINITY = "
                              f"{t.cfg.LENGTH_OF_INFINITY} m): not on the top of a flight")
    return end("completed", f"on the floor, or a landing: no edge within {searched:.2f} m "
                            f"behind step {ctx.steps_descended} from the top, the last "
                            "descended")


_to_edge = reading_drive(-1, _tab, _edge_fallback, _at_edge,
                         lambda t, w: _edge_or_tab(t, w, refind=True), exact=True)


def refind_max_m(cfg: RobotConfig) -> float:
    """The farthest finding the floor again drives forward: back over the
    whole clearance, what the pair's lag may have carried it past, and 2 cm."""
    return edge_clearance_m(cfg) + edge_sight_m(cfg, cfg.wheel_speed_m_s) + 0.02


def _refind(t: Tick, w: Work) -> Step:
    """Drive forward until the back pair reads the floor again (REFIND_TICKS
    ticks in a row, and at least as far as its lag carries the robot at full
    speed), then back up to the edge, the watch seeing it cross."""
    cfg = t.cfg
    assert w.refind_from is not None
    driven_m = (motion.wheel_position(t.snap) - w.refind_from) * cfg.wheel_circumference
    w.refind_floor = 0 if _sees_drop(t) else w.refind_floor + 1
    if w.refind_floor >= REFIND_TICKS and driven_m >= edge_sight_m(cfg, cfg.wheel_speed_m_s,
                                                                   t.ctx.from_top):
        t.say(f"SBR/SBL read the floor again {driven_m * 1000:.0f} mm forward: backing up "
              "to the edge")
        w.refind_from, w.edge_blind_until = None, None
        w.edge_watch_s = w.edge_floor_s = t.snap.time_s
        return stay(NO_MOTION)
    most = refind_max_m(cfg)
    if driven_m >= most and t.ctx.from_top:
        return end("stopped", f"refused: SBR/SBL read past an edge from the start of step "
                              f"{t.ctx.steps_descended + 1} from the top, and still after "
                              f"driving {driven_m * 1000:.0f} mm forward: the tread is shorter "
                              "than the robot")
    if driven_m >= most:
        return fail(f"descent 1: SBR/SBL still read past the edge after driving "
                    f"{driven_m * 1000:.0f} mm forward to find the floor again (at most "
                    f"{most * 1000:.0f} mm): the edge of the step cannot be found")
    return stay(motion.drive(cfg, 1, cfg.wheel_turns(most - driven_m)))


def _to_edge_step(t: Tick, w: Work) -> Step:
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
    return _refind(t, w)


def _turn_square(t: Tick, w: Work) -> Step:
    """Lift segments 1 and 3 and turn on segment 2's wheels by the odometer
    (calibration's turn to a heading), square to the edge; then back up to
    it again, finding the floor first (the pair is past the edge now)."""
    ctx = t.ctx
    assert w.square_yaw is not None
    ctx.edge_squared = True
    ctx.turn_to = motion.twist(t.snap) + motion.yaw_turns(t.cfg, w.square_yaw)
    ctx.purpose = "edge"
    return go(P.CAL_LIFT, f"turning {math.degrees(w.square_yaw):+.1f}° square to the edge")


BACK_TO_EDGE = PhaseDef(
    P.DESCENT_BACK_TO_EDGE, "descent 1 — back up to the edge", FLOW,
    checked_first(_edge_known, _to_edge_step), enter=_to_edge[0], watches="front",
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
        P.ERROR: "tab_length_to_edge[i] unknown; the floor not found again; one back "
                 "sensor reads the drop and the other not within MAX_EDGE_YAW_RAD; " + FAULT})


# -- descent 2: lower segment 3 until the back sensors find the step below ------------------------
def _lower_third_enter(t: Tick, w: Work) -> None:
    t.ctx.return_mtb = w.entry_mtb
    w.target_mtb = -t.cfg.MAX_OF_VERTICAL_TURNS


FLOOR_SIGMAS = 2.0
"""Descent 2: SBR/SBL "read BACK_CLEARANCE" within this many sigmas of their
filtered mean (and half a resolution step)."""


def floor_tolerance(cfg: RobotConfig) -> float:
    """How far above BACK_CLEARANCE the pair's mean may read and segment 3
    stand on the floor: half a resolution step, and FLOOR_SIGMAS sigmas of
    the mean of two filtered readings there.  Without the sigmas, a noisy
    pair (or a cone, whose slanted rays read a little long) that reads above
    BACK_CLEARANCE standing keeps the lift pushing segment 3 down, and
    segment 2 tips nose down (found by the envelope sweep on the reference robot:
    15 deg at the top of a flight)."""
    sigma = median_sigma(cfg, True, cfg.BACK_CLEARANCE) / math.sqrt(2.0)
    return cfg.sensors.resolution / 2 + FLOOR_SIGMAS * sigma


def _over_an_edge(t: Tick, _w: Work) -> Step | None:
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
    t.ctx.end_reason = why
    return go(P.DESCENT_REFUSE, why)


def lowerable_m(cfg: RobotConfig, mtb: float) -> float:
    """How far segment 3 can go down from MTB's counter ``mtb``: to
    -MAX_OF_VERTICAL_TURNS."""
    return max(0.0, cfg.MAX_OF_VERTICAL_TURNS + mtb) * cfg.motors.lift_travel_per_turn


def _deep_drop(t: Tick, w: Work) -> Step | None:
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


def _lower_third(t: Tick, w: Work) -> Step:
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
        ctx.number_of_turns_for_step_height = ctx.return_mtb - t.snap.turns(MotorId.MTB)
        ctx.third_in_air = False  # on the step below
        ctx.narrow_edge_wheel = None  # the next edge's, if narrow, is watched for
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
    enter=_lower_third_enter, watches="back", carried_by=(1, 2),
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


def _refuse_enter(t: Tick, w: Work) -> None:
    w.target_mtb = t.ctx.return_mtb  # where descent 2 began lowering


def _refuse(t: Tick, w: Work) -> Step:
    cfg = t.cfg
    speeds = motion.lifts_to(cfg, t.snap, w.lift_targets())
    if speeds is not None:
        return stay(speeds)
    here = motion.wheel_position(t.snap)
    if w.target_wheel is None:
        w.target_wheel = here + cfg.wheel_turns(edge_clearance_m(cfg) + RETREAT_MARGIN_M)
    remaining = w.target_wheel - here
    if remaining <= motion.WHEEL_DONE:
        why = t.ctx.end_reason or f"refused the drop below step {t.ctx.steps_descended + 1}"
        return end("stopped", f"{why}; segment 3 raised again, the robot back on the step")
    return stay(motion.drive(cfg, 1, remaining))


REFUSE = PhaseDef(
    P.DESCENT_REFUSE, "descent 2 — refused: raise segment 3, drive back onto the step", FLOW,
    _refuse, enter=_refuse_enter, carried_by=(1, 2),
    to={P.DONE: "segment 3 raised to where descent 2 began, and driven forward "
                "edge_clearance_m and RETREAT_MARGIN_M: the robot on the step (stopped)",
        P.ERROR: FAULT})


# -- descent 3-6: segment by segment off the step ----------------------------------------------
def _second_target(t: Tick) -> float | None:
    tab = _tab(t)
    return None if tab is None else t.cfg.LENGTH_OF_SECOND_MODULE + tab


def _first_target(t: Tick) -> float | None:
    tab = _tab(t)
    if tab is None:
        return None
    return t.cfg.LENGTH_OF_FIRST_MODULE + t.cfg.LENGTH_OF_SECOND_MODULE + tab


DRIVE_SECOND = drive_phase(
    P.DESCENT_DRIVE_SECOND, "descent 3 — drive segment 2 off the step", FLOW, -1,
    _second_target, lambda t: t.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_SECOND_MODULE,
    P.DESCENT_LOWER_SECOND, "reads LENGTH_OF_SECOND_MODULE + tab_length_to_edge[i] "
    "(or turns made)")

LOWER_SECOND = lift_phase(
    P.DESCENT_LOWER_SECOND, "descent 4 — lower segment 2", FLOW,
    lambda t, _w: {MotorId.MTF: _h(t), MotorId.MTB: _h(t)}, P.DESCENT_DRIVE_FIRST, (1, 3))

def _first_bound(t: Tick, w: Work) -> float | None:
    """Descent 5 onto a narrow tread: watch its edge (:func:`_narrow_bound`);
    the drive's own target is not bounded."""
    _narrow_bound(t, w, t.descent_index - 1)
    return None


def _driven_first(t: Tick, _w: Work) -> Step:
    # on a narrow tread below, segment 3 has backed off its edge: in the air over the next
    t.ctx.third_in_air = _narrow(t, t.descent_index - 1)
    return go(P.DESCENT_LOWER_FIRST)


DRIVE_FIRST = drive_phase(
    P.DESCENT_DRIVE_FIRST, "descent 5 — drive segment 1 off the step", FLOW, -1,
    _first_target, lambda t: t.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE,
    P.DESCENT_LOWER_FIRST, "reads LENGTH_OF_FIRST_MODULE + LENGTH_OF_SECOND_MODULE + "
    "tab_length_to_edge[i] (or turns made); onto a narrow tread, segment 3 is in the air now",
    _driven_first, _first_bound)


def _lowered_first(t: Tick, _w: Work) -> Step:
    ctx = t.ctx
    ctx.steps_descended += 1
    if ctx.from_top:
        t.say(f"step {ctx.steps_descended} from the top descended",
              steps_descended=ctx.steps_descended)
        return go(P.DESCENT_BACK_OFF)
    t.say(f"step {ctx.number_of_steps - ctx.steps_descended + 1} descended "
          f"({ctx.steps_descended} of {ctx.number_of_steps})", steps_descended=ctx.steps_descended)
    if ctx.steps_descended < ctx.number_of_steps:
        return go(P.DESCENT_BACK_OFF)
    ctx.turned_back = False  # descent 7 turns back to the floor's heading once
    return go(P.DESCENT_FINISH)


_lower1 = lift(lambda t, _w: {MotorId.MTF: -_h(t)}, _lowered_first)
LOWER_FIRST = PhaseDef(
    P.DESCENT_LOWER_FIRST, "descent 6 — lower segment 1", FLOW, _lower1[1], enter=_lower1[0],
    carried_by=(2, 3),
    to={P.DESCENT_BACK_OFF: "turns made; steps remain (a continuous descent: always)",
        P.DESCENT_FINISH: "turns made; all number_of_steps descended", P.ERROR: FAULT})


# -- descent 7: back to the start ----------------------------------------------------------------
def _on_the_floor_all_along(t: Tick) -> bool:
    """No step was climbed: the wheels drove only on the floor, and their
    odometer knows the way back better than a reading of stairs it refused
    (a cone may see over low risers there)."""
    return t.ctx.number_of_steps == 0 and t.ctx.start_wheel is not None


def _finish_turns(t: Tick) -> float:
    """How far descent 7 backs while the front pair cannot measure: by the
    odometer if no step was climbed; else from the riser (approach_gap
    away) to the start reading -- not the seed's
    NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH, which a pair that reads from
    10 cm (a Sharp) had not yet measured within, and stopped 0.4 m short."""
    ctx, cfg = t.ctx, t.cfg
    if _on_the_floor_all_along(t):
        assert ctx.start_wheel is not None
        return max(0.0, motion.wheel_position(t.snap) - ctx.start_wheel)
    if ctx.start_reading is None:
        return cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH
    return cfg.wheel_turns(max(0.0, ctx.start_reading - cfg.algorithm.approach_gap))


def _closed_in_turns(t: Tick) -> float:
    """How far the first calibration closed in before it squared up (turns)."""
    ctx = t.ctx
    if ctx.start_wheel is None or ctx.home_wheel is None:
        return 0.0
    return max(0.0, ctx.start_wheel - ctx.home_wheel)


def _at_start_position(t: Tick, _w: Work) -> Step:
    """At the start position (where the first calibration squared up).  If it
    closed in first, the way home retraces it: turn back to the heading the
    program began with (segments 1 and 3 lifted, as calibration turns), then
    back the distance."""
    ctx = t.ctx
    if _closed_in_turns(t) <= motion.WHEEL_DONE:
        return end("completed", "back at the start position")
    if ctx.home_twist is None or abs(heading_off_rad(t, ctx.home_twist)) <= HEADING_TOLERANCE_RAD:
        return go(P.DESCENT_FINISH_FLOOR)
    ctx.purpose = "home"
    ctx.turn_to = ctx.home_twist
    return go(P.CAL_LIFT)


def _floor_heading(t: Tick, _w: Work) -> Step | None:
    """Before backing to the start position: turn back (once) to the heading
    the robot crossed the floor with, where the first calibration left it
    (climb_twist[0]), if the odometer says it is further off than
    HEADING_TOLERANCE_RAD.  Descent 1 squared up to the first riser again, and
    a start squared up far away within a noisy pair's tolerance may differ
    from that by degrees: backing 0.7 m on the squarer heading put the ir
    robot 5.7 cm to the side of its start (envelope case 304)."""
    ctx = t.ctx
    floor = ctx.climb_twist[0]
    if ctx.turned_back or floor is None:
        return None
    ctx.turned_back = True
    off = heading_off_rad(t, floor)
    if abs(off) <= HEADING_TOLERANCE_RAD:
        return None
    ctx.purpose = "floor"
    ctx.turn_to = floor
    t.say(f"descent 7: turned {math.degrees(off):+.2f}° from the heading it crossed the floor "
          "with (by the odometer); turning back to it", off_deg=math.degrees(off))
    return go(P.CAL_LIFT)


_finish = reading_drive(-1, lambda t: None if _on_the_floor_all_along(t) else t.ctx.start_reading,
                        _finish_turns, _at_start_position)
FINISH = PhaseDef(
    P.DESCENT_FINISH, "descent 7 — finish: back off to the start position", FLOW,
    checked_first(_floor_heading, _finish[1]), enter=_finish[0], watches="front",
    to={P.DONE: "reads the start reading (or turns made; with no step climbed: back by the "
                "odometer to the start position)",
        P.CAL_LIFT: "turned from the heading it crossed the floor with: lift to turn back to "
                    "it; or, the first calibration closed in, turned from the heading the "
                    "program began with: lift to turn back",
        P.DESCENT_FINISH_FLOOR: "the first calibration closed in; turned within "
                                "HEADING_TOLERANCE_RAD of the heading it began with",
        P.ERROR: FAULT})


_floor = turns_drive(-1, _closed_in_turns,
                     lambda _t, _w: end("completed", "back where the program began"))
FINISH_FLOOR = PhaseDef(
    P.DESCENT_FINISH_FLOOR, "descent 7 — finish: back the distance calibration closed in",
    FLOW, _floor[1], enter=_floor[0],
    to={P.DONE: "turns made: where the program began", P.ERROR: FAULT})

PHASES: tuple[PhaseDef, ...] = (
    BACK_OFF, BACK_TO_EDGE, LOWER_THIRD, REFUSE, DRIVE_SECOND, LOWER_SECOND, DRIVE_FIRST,
    LOWER_FIRST, FINISH, FINISH_FLOOR,
)
