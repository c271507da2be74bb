"""Landing 1's scan: segment 3 lifted its whole stroke, the side pair (SSR,
SSL) looking out for the next flight (:mod:`~stairbot.control.algorithm.landing`
decides what it found)."""

from __future__ import annotations

import statistics
from collections.abc import Callable

from stairbot.control.algorithm import limits, motion
from stairbot.control.algorithm.families import LandingTurn
from stairbot.control.algorithm.moves import stood
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
from stairbot.control.algorithm.texts import landing as say
from stairbot.control.algorithm.work import RecheckWork, ScanWork
from stairbot.control.tolerances import side_settle_s
from stairbot.hardware import SIDE_SENSORS, MotorId, SensorReading, SensorStatus

P = Phase
FLOW = "landing"

SIDE_JUMP_M = 0.05
"""A side sees over what it saw when it reads this much farther (or nothing
in range): ascent 3's SIGHT_JUMP_M, for the same reason -- no tread is this
short, and it is ten times the sensors' noise."""
SCAN_CONFIRM_TICKS = 5
"""Lifting, a side has been seen over once its reading has stayed past what
it saw this many ticks in a row (then the lift may stop early)."""
SCAN_TOP_TICKS = 15
"""Standing at the top of the scan, the ticks each side is read over: open
if past what it saw on most of them."""
SCAN_BASE_M = 0.01
"""The scan takes what each side sees from the readings of its first this
much of segment 3's lift, m."""
LEFT, RIGHT = 1, -1


# -- landing 1: scan ---------------------------------------------------------------------
def _side(reading: SensorReading) -> float | None:
    """A side reading's distance, or None (nothing in range, or an error)."""
    return reading.distance_m if reading.ok else None


def _scan_enter(t: Tick, w: ScanWork) -> None:
    t.ctx.landing.seen = True
    t.ctx.family_of(LandingTurn).return_mtb = w.entry_mtb
    w.target_mtb = max(w.entry_mtb, t.cfg.MAX_OF_VERTICAL_TURNS)


def _lifted_m(t: Tick, w: ScanWork) -> float:
    return (t.snap.turns(MotorId.MTB) - w.entry_mtb) * t.cfg.motors.lift_travel_per_turn


def _jumped(reading: SensorReading, base: float) -> bool:
    """The side reads on past what it saw (by SIDE_JUMP_M, or nothing in range)."""
    if reading.status is SensorStatus.OUT_OF_RANGE:
        return reading.distance_m > base
    return reading.ok and reading.distance_m >= base + SIDE_JUMP_M


def _sample(t: Tick, w: ScanWork) -> None:
    """Lifting, per side (SSR, SSL): the readings of the lift's first
    SCAN_BASE_M (what the side sees), then the height from which the reading
    has stayed past them SCAN_CONFIRM_TICKS ticks in a row (where the beam
    saw over what it saw: a hint of the riser's height)."""
    lifted = _lifted_m(t, w)
    for i, sid in enumerate(SIDE_SENSORS):
        reading = t.snap.sensors[sid]
        if lifted < SCAN_BASE_M:
            d = _side(reading)
            if d is not None:
                w.side_base[i].append(d)
            continue
        if not w.side_base[i] or w.side_run[i] >= SCAN_CONFIRM_TICKS:
            continue
        if _jumped(reading, statistics.median(w.side_base[i])):
            if w.side_run[i] == 0:
                w.side_open[i] = lifted
            w.side_run[i] += 1
        else:
            w.side_run[i], w.side_open[i] = 0, None


def _scan(t: Tick, w: ScanWork) -> Step:
    """Lift segment 3 to the top of its stroke (or until both sides have been
    seen over), then, standing, read both sides SCAN_TOP_TICKS ticks once
    the filter has settled: a side is open only if what it reads standing
    there lies past what it saw below.  A stray measurement while lifting
    (1 % outliers) took a wall for a flight: the robot turned to it."""
    if not w.lifted:
        _sample(t, w)
        speeds = motion.lifts_to(t.cfg, t.snap, w.lift_targets())
        if speeds is not None and min(w.side_run) < SCAN_CONFIRM_TICKS:
            return stay(speeds)
        w.lifted = True
    if not stood(t, w, side_settle_s(t.cfg)):
        return stay(NO_MOTION)
    for i, sid in enumerate(SIDE_SENSORS):
        reading = t.snap.sensors[sid]
        if not w.side_base[i]:
            continue
        w.side_top[i] += 1 if _jumped(reading, statistics.median(w.side_base[i])) else 0
    w.side_ticks += 1
    if w.side_ticks < SCAN_TOP_TICKS:
        return stay(NO_MOTION)
    return _record(t, w)


def _record(t: Tick, w: ScanWork) -> Step:
    """What the scan found: how far each side is from the centre line (kept
    in the context for the turn and the way back), which sides open onto a
    flight, and its first riser's height (where the beam saw over it: kept
    for the decision)."""
    landing, cfg, turn = t.ctx.landing, t.cfg, t.ctx.family_of(LandingTurn)
    lat = cfg.sensors.side_lateral
    bases = [statistics.median(b) if b else None for b in w.side_base]
    landing.right_m = None if bases[0] is None else bases[0] + lat
    landing.left_m = None if bases[1] is None else bases[1] + lat
    # open: past what it saw on most of the ticks standing at the top, and
    # seen over no lower than the lowest riser it climbs (the beam below that
    # met something it then lost: a fault, not a flight -- a side sensor
    # reading long from just above the landing would otherwise send the robot
    # turning to a wall)
    # The beam must have begun to read past it while rising: standing, nothing
    # moves that could let it see over anything (a reading that changes there
    # is the sensor's doing).
    seen_at = w.side_open
    low = limits.min_step_rise_m(cfg) - cfg.sensors.side_height - SCAN_BASE_M
    opened = [bases[i] is not None and 2 * w.side_top[i] > SCAN_TOP_TICKS
              and (o := seen_at[i]) is not None and o >= low for i in (0, 1)]
    turn.base_m = bases
    turn.rise_m = [o + cfg.sensors.side_height if opened[i] and (o := seen_at[i]) is not None
                   else None for i in (0, 1)]
    turn.open = [s for i, s in ((0, RIGHT), (1, LEFT)) if opened[i]]
    for i, sid in enumerate(SIDE_SENSORS):
        base, at = bases[i], seen_at[i]
        if opened[i] and base is not None and at is not None:
            t.say(say.side_sees_over(sid.value, i == 0, base, at),
                  sensor=sid.value, base=base)
    return go("scanned")


# -- landing 1: lowered, the sides seen over read again ----------------------------------
def recheck(done: Callable[[Tick, RecheckWork], Step]) -> Callable[[Tick, RecheckWork], Step]:
    """Segment 3 lowered again, before ``done`` (the decision): standing once
    the side pair's filter has settled, each side seen over is read
    SCAN_TOP_TICKS ticks.  The beam is back where it read before the lift,
    below the riser it saw over, and nothing else moved: it must read what it
    read there (within SIDE_JUMP_M) on most of them.  One that does not was
    not seeing over the stairs -- its reading moved, not the beam's view (an
    offset that began mid-scan read as a flight: the robot turned into a
    wall) -- and is no flight."""

    def step(t: Tick, w: RecheckWork) -> Step:
        turn = t.ctx.family_of(LandingTurn)
        if not turn.open:
            return done(t, w)
        if not stood(t, w, side_settle_s(t.cfg)):
            return stay(NO_MOTION)
        for i, sid in enumerate(SIDE_SENSORS):
            base = turn.base_m[i]
            d = _side(t.snap.sensors[sid])
            if base is not None and d is not None and abs(d - base) < SIDE_JUMP_M:
                w.side_back[i] += 1
        w.side_ticks += 1
        if w.side_ticks < SCAN_TOP_TICKS:
            return stay(NO_MOTION)
        for i, (sid, side) in enumerate(zip(SIDE_SENSORS, (RIGHT, LEFT), strict=True)):
            base = turn.base_m[i]
            if side in turn.open and base is not None and 2 * w.side_back[i] <= SCAN_TOP_TICKS:
                turn.open.remove(side)
                turn.rise_m[i] = None
                t.say(say.side_not_back(sid.value, i == 0, base, w.side_back[i],
                                        SCAN_TOP_TICKS), sensor=sid.value, base=base)
        return done(t, w)

    return step


SCAN = PhaseDef(
    P.LANDING_SCAN, "landing 1 — lift segment 3, looking sideways for the next flight", FLOW,
    _scan, ScanWork, enter=_scan_enter, carried_by=(1, 2), family=LandingTurn,
    on={"scanned": Exit(P.LANDING_SCAN_LOWER, "segment 3 at the top of its stroke (or both "
                                              "sides seen over), read standing there"),
        FAILED: Exit(P.ERROR, FAULT)})
