"""Descent 1's edge watch: where the back pair (SBR/SBL, looking down under
segment 3) reads the floor and where the drop past an edge, where it saw an
edge go by, and how far backing may go from there.

:func:`edge_bound` bounds descent 1's backing: edge_clearance_m past where
the pair crossed the edge, a crossing placed only when the watch saw it as
it happened (else the robot drives forward until the pair reads the floor
again: :func:`refind`).  In a continuous descent it also squares the robot
up to the edge (:func:`square_to_edge`).  On a narrow step,
:func:`narrow_bound` keeps segment 2's rear axle on the tread.
:func:`floor_tolerance` is how near BACK_CLEARANCE the pair reads the floor.
"""

from __future__ import annotations

import math

from stairbot.control.algorithm import motion
from stairbot.control.algorithm.edge_measure import (
    edge_clearance_m,
    edge_doubt_m,
    edge_drop_m,
    edge_lag_s,
    edge_sight_m,
)
from stairbot.control.algorithm.modes import Outcome
from stairbot.control.algorithm.phase import NO_MOTION, Step, Tick, distrust, end, fail, stay
from stairbot.control.algorithm.texts import descent as say
from stairbot.control.algorithm.work import EdgeWork
from stairbot.control.timeline import keep_since, value_at
from stairbot.control.tolerances import max_age, measurement_period, window
from stairbot.hardware import BACK_SENSORS, SensorId, SensorStatus
from stairbot.inputs.config import RobotConfig

EDGE_GAP_TICKS = 2.5
"""The edge watch missed a stretch when two of its ticks are further apart
than this many control ticks."""
REFIND_TICKS = 3
"""Finding the floor again: ticks in a row the back pair must read it."""


def drops(t: Tick) -> list[bool]:
    """Each of SBR and SBL reads past an edge: more than edge_drop_m, or
    nothing in range."""
    cfg, drop = t.cfg, edge_drop_m(t.cfg, t.ctx.from_top)
    return [r.status is SensorStatus.OUT_OF_RANGE and r.distance_m > cfg.BACK_CLEARANCE
            or r.ok and r.distance_m > drop
            for r in (t.snap.sensors[s] for s in BACK_SENSORS)]


def _off_climb_heading(t: Tick) -> float | None:
    """On a climbed step, how far (radians, + = left) the odometer says the
    robot is turned from the heading it climbed the step with, which
    calibration squared to the riser and descent 1 turns back to (None: not
    known, as in a continuous descent)."""
    ctx = t.ctx
    climbed = None if ctx.from_top else ctx.climb_twist[t.descent_index]
    if climbed is None:
        return None
    return motion.turn_yaw_rad(t.cfg, motion.twist(t.snap) - climbed)


def edge_stopped(w: EdgeWork) -> Step:
    """The step's answer to the watch's stop (``w.edge_stop``): a back
    sensor judged wrong is distrusted, and the step goes on (if perception
    judges it so, it is lost and the robot limps home on its partner: the
    watch finds the floor again and the edge with the survivor); else the
    program ends with the error."""
    stop, wrong = w.edge_stop, w.edge_wrong
    assert stop is not None
    if wrong is None:
        return fail(stop)
    w.edge_stop = w.edge_wrong = None
    return distrust(wrong, stop)


def sees_drop(t: Tick) -> bool:
    """The back pair reads past an edge: both of them."""
    return all(drops(t))


EDGE_SQUARE_RAD = math.radians(3.0)
"""Continuous descent: turned further than this from square to the edge (by
how far it backed between SBR and SBL reading the drop), the robot turns
square before it backs on: askew, backing the whole clearance from the
second sensor's crossing takes segment 2's wheels on the first one's side
over the edge.  The estimate's own error is about one measurement period's
backing across the pair's spacing (3 deg for an HC-SR04 pair), and the
threshold stays just above it."""
MAX_EDGE_YAW_RAD = math.radians(25.0)
"""One back sensor reads the drop and the other still the floor after the
robot backed as far as this yaw across the pair's spacing: it stops."""


def square_to_edge(t: Tick, w: EdgeWork) -> str | None:
    """Watch which back sensor reads the drop first, and where
    (``w.edge_first_wheel``: :func:`_crossed` places the crossing between
    the two); an error if the other does not follow within
    MAX_EDGE_YAW_RAD.  In a continuous descent, once both do, the yaw to
    square up (``w.square_yaw``), if more than EDGE_SQUARE_RAD and not
    squared at this edge yet.  Only on a crossing the watch sees as it
    happens (``w.edge_floor_s``).  Returns the error that ends the program,
    if any.  On a climbed step calibration has squared the robot to the
    edge, so one sensor reading the drop far before the other is a sensor
    reading wrong, not a yaw: placing the crossing half-way between them
    would stop the robot short, and lowering segment 3 there tips it nose
    down."""
    ctx, cfg = t.ctx, t.cfg
    if ctx.descent.edge_wheel is not None or w.edge_floor_s is None:
        return None
    right, left = drops(t)
    here = motion.wheel_position(t.snap)
    if not right and not left:
        w.edge_first_wheel = w.edge_first = None  # both on the floor: no crossing begun
        return None
    if right != left:
        first = SensorId.SBR if right else SensorId.SBL
        if w.edge_first_wheel is None or w.edge_first != first:
            w.edge_first_wheel, w.edge_first = here, first
        lag = (w.edge_first_wheel - here) * cfg.wheel_circumference
        most = 2 * cfg.sensors.back_lateral * math.tan(MAX_EDGE_YAW_RAD)
        if lag > most:
            other = SensorId.SBL if right else SensorId.SBR
            off = _off_climb_heading(t)
            if off is not None and abs(off) <= EDGE_SQUARE_RAD and not w.edge_distrusted:
                # square by the odometer: no yaw explains the lag, the
                # sensor still reading the floor is wrong
                w.edge_wrong, w.edge_distrusted = other, True
                return say.missed_crossing(first, lag, most, MAX_EDGE_YAW_RAD, off)
            return say.edge_askew(first, other, lag, most, MAX_EDGE_YAW_RAD)
        return None
    if not ctx.from_top:
        return None
    if right and w.edge_first_wheel is not None and not ctx.descent.edge_squared:
        lag = (w.edge_first_wheel - here) * cfg.wheel_circumference
        yaw = math.atan2(lag, 2 * cfg.sensors.back_lateral)
        if yaw > EDGE_SQUARE_RAD:
            # SBR first: its side is further back, the robot turned right: turn left
            w.square_yaw = yaw if w.edge_first is SensorId.SBR else -yaw
            t.say(say.drop_read_first(w.edge_first, lag, yaw, w.square_yaw),
                  edge_yaw_deg=math.degrees(w.square_yaw))
    return None


def edge_bound(t: Tick, w: EdgeWork, refind: bool) -> float | None:
    """Descent 1's backing (backing off, and backing up to the edge) never
    passes edge_clearance_m beyond where the back pair saw the drop (more
    than half the lowest rise below BACK_CLEARANCE, or nothing in range):
    tab_length_to_edge, read on the way up, may be a centimetre or two off,
    enough to tip the robot back; and on a tread little longer than the
    robot, backing off the seed's approach turns already takes segment 3
    past the edge, and backing up to the edge by the tab after that would
    tip it back.

    Where the pair crossed is worked out only from a crossing the watch saw
    as it happened: the pair read the floor on a tick of this phase, then
    the drop, with no stretch between missed.  Otherwise -- the pair already
    past the edge when the phase began (it crossed as the back-off ended,
    or while calibration turned), or a tick came late (a stalled host: the
    robot ran on unwatched) -- where it crossed is not known: the back-off
    ends where it is, and backing up to the edge first drives forward until
    the pair reads the floor again (``refind``: :func:`refind`).  A
    crossing placed at the tick that first saw the drop after such a gap
    (the robot standing, so :func:`edge_sight_m` is 0) would lie at the
    pair, when the pair may be well past the edge, and backing the whole
    clearance from there tips the robot back."""
    cfg, step = t.cfg, t.ctx.descent
    if step.edge_wheel is None:
        now = t.snap.time_s
        if w.square_yaw is None and w.edge_stop is None:
            w.edge_stop = square_to_edge(t, w)
        if w.edge_stop is not None or w.square_yaw is not None:
            # the step wrapper ends the program, or turns square first (the
            # back-off ends here and turns)
            return None if refind else motion.wheel_position(t.snap)
        here = motion.wheel_position(t.snap)
        if w.edge_watch_s is not None \
                and now - w.edge_watch_s > EDGE_GAP_TICKS * cfg.algorithm.tick:
            _missed_stretch(t, w, here)
        w.edge_watch_s, w.edge_watch_wheel = now, here
        _remember(t, w, here)
        if not sees_drop(t):
            if w.edge_blind_until is None or now > w.edge_blind_until:
                _floor_read(t, w, here)
        elif w.edge_floor_s is None or w.edge_floor_held and not held_crossing_known(t, w):
            if refind:
                w.refind_from = motion.wheel_position(t.snap)
                w.refind_floor = 0
                t.say(say.NOT_SEEN_CROSSING)
                return None
            return motion.wheel_position(t.snap)  # the back-off ends here
        else:
            step.edge_wheel, sight = _crossed(t, w, w.edge_first_wheel)
            if w.edge_floor_held:
                step.edge_wheel = held_crossing(t, w, step.edge_wheel)
                sight = (step.edge_wheel - here) * cfg.wheel_circumference
            more = max(0.0, edge_clearance_m(cfg) - sight)
            t.say(say.sees_edge(motion.mean_distance(t.snap, back=True), sight, more))
    if step.edge_wheel is None:
        return None
    return step.edge_wheel - cfg.wheel_turns(edge_clearance_m(cfg))


def floor_known_s(t: Tick) -> float:
    """How long ago, at the latest, the measurements behind the back pair's
    present floor reading put both sensors on the floor: its newest
    measurement's age (the boards' count, perception's), then the older half
    of the median's window, one period each.  Past that the pair may have
    crossed unseen."""
    cfg = t.cfg
    age = max(t.snap.sensors[s].age_s for s in BACK_SENSORS)
    return age + (window(cfg, True) // 2) * measurement_period(cfg, True)


def _history_s(cfg: RobotConfig) -> float:
    """How far back the watch keeps the odometer: the oldest a floor reading
    can stand for (:func:`floor_known_s` at the stale limit), and a tick."""
    return max_age(cfg, True) + (window(cfg, True) // 2 + 1) * measurement_period(cfg, True) \
        + cfg.algorithm.tick


def _remember(t: Tick, w: EdgeWork, here: float) -> None:
    w.edge_recent.append((t.snap.time_s, here))
    keep_since(w.edge_recent, t.snap.time_s - _history_s(t.cfg))


def _floor_read(t: Tick, w: EdgeWork, here: float) -> None:
    """The pair reads the floor on a watched tick: a crossing seen from here
    on is placed as it happens; and where the pair was when its measurements
    last put it on the floor (``edge_floor_at``) bounds a crossing read after
    a stretch the robot stood through."""
    w.edge_floor_s = t.snap.time_s
    w.edge_floor_at = value_at(w.edge_recent, t.snap.time_s - floor_known_s(t))
    w.edge_floor_held = False


def _missed_stretch(t: Tick, w: EdgeWork, here: float) -> None:
    """The watch missed a stretch (a tick came late, a hold).  What
    perception says of the pair until its lag has passed still comes from
    measurements taken before or in it: a floor read until then does not
    count.  If the wheels moved through the stretch no further than the
    crossing's own doubt (:func:`edge_doubt_m`) -- the robot stood, every
    motor stopped -- the floor read before it still bounds where the pair
    can have crossed (``edge_floor_held``).  Otherwise the robot ran on
    unwatched, and that floor no longer counts either."""
    cfg = t.cfg
    w.edge_blind_until = t.snap.time_s + edge_lag_s(cfg) + measurement_period(cfg, True)
    last = w.edge_watch_wheel
    if last is not None and abs(here - last) * cfg.wheel_circumference <= edge_doubt_m(cfg):
        w.edge_floor_held = w.edge_floor_s is not None
        return
    w.edge_floor_s = w.edge_floor_at = w.edge_first_wheel = w.edge_first = None
    w.edge_floor_held = False


def held_crossing_known(t: Tick, w: EdgeWork) -> bool:
    """A drop read after a stretch the robot stood through: the crossing lies
    between where the floor reading before it put the pair and here.  Known
    well enough when that span is within the crossing's doubt
    (:func:`edge_doubt_m`, which the clearance carries): the crossing is then
    placed at the span's far end (:func:`held_crossing`), never further back
    than it can be, and the robot stops short of where a watched crossing
    would stop it by no more than that doubt.  Backing at full speed the
    span is the pair's lag's worth of backing, more than the doubt; backing
    slowly after finding the floor again
    (:func:`~stairbot.control.algorithm.edge_measure.slow_backing`), less."""
    if w.edge_floor_at is None:
        return False
    span = (w.edge_floor_at - motion.wheel_position(t.snap)) * t.cfg.wheel_circumference
    return span <= edge_doubt_m(t.cfg)


def held_crossing(t: Tick, w: EdgeWork, crossed: float) -> float:
    """The crossing of a drop read after a stretch the robot stood through:
    ``crossed`` (where a watched crossing would be placed), or the far end of
    the span the floor reading before the stretch leaves, if further
    forward: that reading's position plus how far past the edge the pair
    may still read the floor (:func:`edge_sight_m` standing: a first-echo
    sensor's riser face, a signal-mixing cone's footprint)."""
    assert w.edge_floor_at is not None
    face = t.cfg.wheel_turns(edge_sight_m(t.cfg, 0.0, t.ctx.from_top))
    return max(crossed, w.edge_floor_at + face)


def _crossed(t: Tick, w: EdgeWork, first_wheel: float | None = None) -> tuple[float, float]:
    """Where the back pair crossed the edge whose drop it reads now for the
    first time, on the odometer, and how far past it the pair is: what the
    wheels backed over the pair's lag (:func:`edge_lag_s`), by the
    odometer's record of the watched ticks (``w.edge_recent``), plus what
    the cone lets the pair see (:func:`edge_sight_m` standing: a first-echo
    sensor's riser face, a signal-mixing cone's footprint still on the
    tread).  By the record, not the speed now times the lag: a drop read
    as the backing brakes (at its end, or into a hold) was measured while
    the robot backed faster, the speed now would place the crossing too far
    back, and backing the clearance from there tips the robot back.  Behind
    the robot's back (backing, the odometer runs down), so at a larger
    count.  If one sensor
    read the drop first (at ``first_wheel``), the crossing is placed
    half-way between the two: where the robot's centre line crossed, the
    pair being mounted either side of it; placed where the second sensor
    read it, the crossing is up to half the gap too near, and backing the
    rest of the clearance from there tips the robot back.  The gap counts
    less what one measurement period's backing explains
    (:func:`edge_doubt_m`): the two sensors measure at their own times, and
    that much of the gap is timing, not yaw; counted in full it would stop
    segment 3's front wheels on the corner, and lowering it there tips the
    robot nose down."""
    cfg = t.cfg
    here = motion.wheel_position(t.snap)
    backed = value_at(w.edge_recent, t.snap.time_s - edge_lag_s(cfg)) - here
    sight = backed * cfg.wheel_circumference + edge_sight_m(cfg, 0.0, t.ctx.from_top)
    if first_wheel is not None:
        # what one measurement period's backing explains is the sensors'
        # timing, not where they crossed (edge_doubt_m covers it)
        apart = max(0.0, (first_wheel - here) * cfg.wheel_circumference - edge_doubt_m(cfg))
        return here + cfg.wheel_turns(sight + apart / 2), sight + apart / 2
    return here + cfg.wheel_turns(sight), sight


NARROW_AXLE_MARGIN_M = 0.004
"""On a narrow step, descent 1 never backs segment 2's rear axle nearer the
edge than this (the tab puts it 8.5 mm past it, as ascent 6 left it)."""


def narrow_bound(t: Tick, w: EdgeWork) -> float | None:
    """Narrow steps: watch the back pair cross the edge of the narrow tread
    the robot stands on, or steps down onto (floor, then the drop, as
    :func:`edge_bound` does) and
    keep where (``DescentStep.narrow_edge_wheel``); once known, the odometer
    count the backing never passes: segment 2's rear axle
    NARROW_AXLE_MARGIN_M past that edge, counted from where the pair may
    have crossed it at the earliest: :func:`_crossed` places it (a
    signal-mixing cone's footprint counted, :func:`edge_sight_m`), and the
    crossing falls anywhere in a measurement period (:func:`edge_doubt_m`).
    The front pair's tab alone leaves 8.5 mm to spare there: both of its
    sensors reading 20 mm short (a common fault the standing rule cannot
    see) would back segment 2's rear wheels off the edge."""
    cfg, step = t.cfg, t.ctx.descent
    if step.narrow_edge_wheel is None:
        _remember(t, w, motion.wheel_position(t.snap))
        if not sees_drop(t):
            w.edge_floor_s = t.snap.time_s
        elif w.edge_floor_s is not None:
            step.narrow_edge_wheel = _crossed(t, w)[0]
    if step.narrow_edge_wheel is None:
        return None
    g = cfg.geometry
    reach = g.LENGTH_OF_THIRD_MODULE - cfg.sensors.back_from_rear + g.wheel_inset
    return step.narrow_edge_wheel - cfg.wheel_turns(reach - NARROW_AXLE_MARGIN_M
                                                    - edge_doubt_m(cfg))


def refind_max_m(cfg: RobotConfig) -> float:
    """The farthest finding the floor again drives forward: back over the
    whole clearance, what the pair's lag may have carried it past, and 2 cm."""
    return edge_clearance_m(cfg) + edge_sight_m(cfg, cfg.wheel_speed_m_s) + 0.02


def refind(t: Tick, w: EdgeWork) -> Step:
    """Drive forward until the back pair reads the floor again (REFIND_TICKS
    ticks in a row, and at least as far as its lag carries the robot at full
    speed), then back up to the edge, the watch seeing it cross."""
    cfg = t.cfg
    assert w.refind_from is not None
    driven_m = (motion.wheel_position(t.snap) - w.refind_from) * cfg.wheel_circumference
    w.refind_floor = 0 if sees_drop(t) else w.refind_floor + 1
    if w.refind_floor >= REFIND_TICKS and driven_m >= edge_sight_m(cfg, cfg.wheel_speed_m_s,
                                                                   t.ctx.from_top):
        t.say(say.floor_again(driven_m))
        w.edge_slow = True
        w.refind_from = w.edge_blind_until = w.edge_first_wheel = w.edge_first = None
        here = motion.wheel_position(t.snap)
        w.edge_watch_s, w.edge_watch_wheel = t.snap.time_s, here
        _remember(t, w, here)
        _floor_read(t, w, here)
        return stay(NO_MOTION)
    most = refind_max_m(cfg)
    if driven_m >= most and t.ctx.from_top:
        return end(Outcome.STOPPED, say.tread_shorter_than_robot(t.ctx.steps_descended,
                                                                 driven_m))
    if driven_m >= most:
        return fail(say.floor_not_refound(driven_m, most))
    return stay(motion.drive(cfg, 1, cfg.wheel_turns(most - driven_m)))
