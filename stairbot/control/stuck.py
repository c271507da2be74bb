"""Stuck distance sensors: fresh measurements whose value no longer changes
where the robot's own motion says it must have (issue 33).

A sensor whose ADC or firmware froze repeats its last distance as a new
measurement: its age is that of a working sensor, so staleness does not see
it.  What gives it away is a value that stays the same (the very value, after
the sensor's rounding) for REPEATS measurements in a row or more while the
robot moved what it looks at:

* **the drive** (SFR, SFL, with segment 2 level: LEVEL_DEG): the front pair
  looks along the drive, and driving d towards (or away from) any flat
  surface a beam meets shortens (lengthens) that beam by d; a cone's mix, or
  a nearest echo, moves with it.  So a value that stays the same while the
  odometer moved more than :func:`drive_limit` (STUCK_MOVE_M, or RESOLUTIONS
  of the sensor's rounding if more: rounding hides less than one step) is
  stuck.  A value "too near" says only that the surface is nearer than the
  minimum: backing away more than the minimum (and the limit) must end it.
* **its partner** (both pairs): the two sensors of a pair look at the same
  surface.  When the partner's filtered reading moved away from this one's
  value by more than the pair's noise allows
  (:func:`~stairbot.control.tolerances.pair_tolerance`; NEAR_JUMP_M for a
  value "too near") -- smoothly (the surface moved), or in a jump from where
  it agreed with this one (it crossed an edge this one stands on the same
  side of) -- and the robot moved on PARTNER_LIFT_M of lift or
  PARTNER_DRIVE_M of drive after that, this one should have followed.  A
  lift moves both sensors of a pair alike; a drive may carry a pair over
  an edge a little apart (askew), hence its margin.  The back pair has only
  this rule: a drive along a tread does not change what it reads, and
  whether a lift moves segment 3 (and the sensors) or segment 2 depends on
  which segments stand, which perception does not know.

A robot standing still, or turning on the spot with a noiseless sensor,
reads the same value for as long as it likes: neither rule fires, since
nothing moved.  A sensor reading "nothing within range" or an error is not
judged (it has no value to be stuck at).  Judged stuck, a sensor reads as
ERROR (:meth:`StuckWatch.judge`), with why, until its value changes: a
sensor the phase needs then stands the robot and, if it stays so, is lost
(the limp home of :mod:`~stairbot.control.algorithm.limp`).  The side pair
is not judged (nothing limps home on it).
"""

from __future__ import annotations

import math
from collections import deque

from stairbot.control.timeline import value_at
from stairbot.control.tolerances import pair_tolerance, settle_s
from stairbot.hardware import (
    BACK_SENSORS,
    FRONT_SENSORS,
    LIFT_MOTORS,
    WHEEL_MOTORS,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
)
from stairbot.inputs.config import RobotConfig

STUCK_MOVE_M = 0.008
"""The drive's travel that must change a front reading that is not stuck
(at least; see :func:`drive_limit`)."""
RESOLUTIONS = 3
"""... and at least this many steps of the sensor's rounding."""
REPEATS = 7
"""Measurements of one value in a row, at least, before a sensor is stuck:
a noisy sensor that is not stuck repeats a value by chance (a VL53L5CX,
4 mm sigma in 1 mm steps, about one measurement in 14), but seven in a row
while the truth moves 8 mm comes about once in 10^7 (worst at a sigma of
3 mm; a quieter sensor cannot hide the move, a noisier one seldom
repeats)."""
LEVEL_DEG = 1.5
"""The drive rule holds only while segment 2 (the IMU) pitches less than
this: pitched, segment 1's beam may meet a tread ahead at a graze, where a
pitch that changes as the robot drives moves the reading as much as the
drive does, the other way (the ideal robot, noiseless, pitched 3.5 degrees
nose down in ascent 6 onto the top step: its SFL read 0.493 m while the
drive moved 12 mm).  Level, a beam meets risers and walls, which the drive
moves it along.  Without an IMU the pitch is not known: the rule does not
hold."""
PARTNER_JUMP_M = 0.02
"""A partner's filtered reading that moves more than this from one tick to
the next has crossed onto another surface (an edge, the top of a riser; the
drives' jump limit).  Its moves count again once its median has settled
there (:func:`~stairbot.control.tolerances.settle_s`): on the ideal robot
rising past a riser, SFL's median went 0.040, 0.304, 0.320 m as its window
filled with the far riser, and the last 16 mm had SFR, already reading the
far riser, judged stuck."""
PARTNER_LIFT_M = 0.004
"""Lift travel (MTF and MTB) after the partner moved that this one must
have followed: small, as a lift moves a pair alike, and within what the
standing rule allows the back pair in descent 2 beyond the pair's noise
(judged later, the rule stops the robot first, and the run ends there)."""
PARTNER_DRIVE_M = 0.03
"""Wheel travel after the partner moved that this one must have followed: a
pair crossing an edge 17 degrees askew is 30 mm apart along the drive."""
NEAR_JUMP_M = 0.05
"""A value "too near" is judged by its partner only once the partner reads
this much beyond it: askew near a riser one of a pair may read just beyond
the minimum and the other just under it (as segment 1 rose, the reference
robot's SFR read 11 mm beyond, SFL too near).  No tread is shorter (ascent
3's SIGHT_JUMP_M)."""
HISTORY = 32
"""Ticks of odometer and motion kept to place a measurement the board
publishes late (0.64 s at 20 ms, as perception's odometer)."""

_PARTNER = {SensorId.SFR: SensorId.SFL, SensorId.SFL: SensorId.SFR,
            SensorId.SBR: SensorId.SBL, SensorId.SBL: SensorId.SBR}
_OK, _OUT = SensorStatus.OK, SensorStatus.OUT_OF_RANGE
OK, NEAR, FAR = 0, 1, 2
"""What a value is: a distance, the "too near" clamp, the "nothing within
range" clamp."""

Value = tuple[float, int]
"""A reading as this watch takes it: the distance and its kind."""


def drive_limit(cfg: RobotConfig) -> float:
    """How far the drive may move while a front reading stays the same."""
    resolution = cfg.sensors.spec(False).resolution
    if resolution is None:
        resolution = cfg.sensors.resolution
    return max(STUCK_MOVE_M, RESOLUTIONS * resolution)


class _Run:
    """One sensor's current run of measurements of one value, and what its
    partner did meanwhile."""

    __slots__ = ("value", "count", "first_s", "taken_s", "odometer", "last_odometer",
                 "last_motion", "partner", "partner_last", "settled_s", "jumped_from",
                 "evidence", "why")

    def __init__(self, value: Value, taken_s: float, odometer: float, level: bool,
                 motion: tuple[float, float], settled_s: float) -> None:
        self.value = value
        self.count = 1
        self.first_s = self.taken_s = taken_s
        self.odometer: float | None = odometer if level else None
        """The odometer from which the drive counts: at the run's first
        measurement taken level since the last one pitched (None: pitched)."""
        self.last_odometer = odometer
        self.last_motion = motion
        """Wheel and lift travel (any direction) at the latest measurement."""
        self.partner: Value | None = None
        """The partner's value its moves count from (None: none yet)."""
        self.partner_last: Value | None = None
        """... on the last tick."""
        self.settled_s = settled_s
        """Until then the partner's median may be settling on a new surface."""
        self.jumped_from: Value | None = None
        """The partner's value before its last jump."""
        self.evidence: tuple[float, float] | None = None
        """The travel when the partner was first seen to move away."""
        self.why: str | None = None
        """Judged stuck: why."""


class StuckWatch:
    """Judges SFR, SFL, SBR and SBL stuck (see the module docstring).  One per
    :class:`~stairbot.control.perception.Perception`, on its clock."""

    def __init__(self, cfg: RobotConfig) -> None:
        self._cfg = cfg
        self._wheel_m = cfg.wheel_circumference / len(WHEEL_MOTORS)
        self._lift_m = cfg.motors.lift_travel_per_turn
        self._limit = drive_limit(cfg)
        self._runs: dict[SensorId, _Run | None] = dict.fromkeys(FRONT_SENSORS + BACK_SENSORS)
        self._midpoint = {sid: sum(cfg.sensors.range(sid in BACK_SENSORS)) / 2.0
                          for sid in self._runs}
        self._settle = {sid: settle_s(cfg, sid in BACK_SENSORS) for sid in self._runs}
        self._now = 0.0
        self._taken: dict[SensorId, float] = {}
        self._turns: tuple[float, ...] | None = None
        self._travel = (0.0, 0.0)  # wheels, lifts
        self._level = False
        self._odometers: deque[tuple[float, float]] = deque(maxlen=HISTORY)
        self._wheels: deque[tuple[float, float]] = deque(maxlen=HISTORY)
        self._lifts: deque[tuple[float, float]] = deque(maxlen=HISTORY)

    def judge(self, snap: Snapshot, odometer: float, seen: dict[SensorId, SensorReading],
              why: dict[SensorId, str]) -> None:
        """Follow ``snap``'s raw measurements (``odometer``: perception's, now);
        in ``seen`` (perception's filtered readings) make each sensor judged
        stuck read as ERROR, and say why in ``why``."""
        now = self._now = snap.time_s
        self._moved(snap, now, odometer)
        for sid, run in self._runs.items():
            raw = snap.sensors.get(sid)
            if raw is None:
                continue
            taken = now - raw.age_s
            if taken > self._taken.get(sid, -math.inf) + 1e-9:  # a new measurement
                self._taken[sid] = taken
                run = self._measured(sid, run, raw, taken)
            if run is None:
                continue
            # judged once, it stays so while the value holds (the figures as they stand)
            run.why = self._stuck(sid, run, seen) or run.why
            if run.why is not None:
                held = seen.get(sid)
                age = raw.age_s if held is None else held.age_s
                seen[sid] = SensorReading(run.value[0], SensorStatus.ERROR, age)
                why[sid] = run.why

    def _moved(self, snap: Snapshot, now: float, odometer: float) -> None:
        """Add this tick's wheel and lift travel, any direction."""
        turns = tuple(snap.turns(m) for m in WHEEL_MOTORS + LIFT_MOTORS)
        last = self._turns
        if last is not None:
            wheels = sum(abs(a - b) for a, b in zip(turns[:4], last[:4], strict=True))
            lifts = abs(turns[4] - last[4]) + abs(turns[5] - last[5])
            w, li = wheels * self._wheel_m, lifts * self._lift_m
            if w == w and li == li:  # a count that is not a number moves nothing here
                self._travel = (self._travel[0] + w, self._travel[1] + li)
        self._turns = turns
        imu = snap.imu
        self._level = imu is not None and abs(imu.pitch_deg) <= LEVEL_DEG
        self._odometers.append((now, odometer))
        self._wheels.append((now, self._travel[0]))
        self._lifts.append((now, self._travel[1]))

    def _value(self, sid: SensorId, reading: SensorReading | None) -> Value | None:
        """What a reading says for this watch (None: an error, no value)."""
        if reading is None:
            return None
        d = reading.distance_m
        if d - d != 0.0:
            return None
        if reading.status is _OK:
            return d, OK
        if reading.status is _OUT:
            return d, NEAR if d < self._midpoint[sid] else FAR
        return None

    def _measured(self, sid: SensorId, run: _Run | None, raw: SensorReading,
                  taken: float) -> _Run | None:
        """The sensor's run after a new measurement: the same one, longer, if
        it is the run's value again; a new one if it is another value; none
        if it has no value."""
        value = self._value(sid, raw)
        if value is None:
            self._runs[sid] = None
            return None
        odometer = value_at(self._odometers, taken)
        motion = value_at(self._wheels, taken), value_at(self._lifts, taken)
        if run is not None and value == run.value:
            run.taken_s, run.last_odometer, run.last_motion = taken, odometer, motion
            if not self._level:
                run.odometer = None
            elif run.odometer is None:
                run.odometer = odometer
            run.count += 1
            return run
        # the partner's median may be settling on a surface it crossed onto
        # just before: its moves count from when it has
        run = _Run(value, taken, odometer, self._level, motion,
                   self._now + self._settle[_PARTNER[sid]])
        self._runs[sid] = run
        return run

    def _stuck(self, sid: SensorId, run: _Run, seen: dict[SensorId, SensorReading]
               ) -> str | None:
        """Why the run says the sensor is stuck, or None."""
        partner = self._partner(sid, run, seen)  # followed every tick
        if run.count < REPEATS:
            return None
        v, kind = run.value
        held = (f"stuck at {v:.3f} m" if kind == OK else f"stuck reading too near (under "
                f"{v:.3f} m)") + f" for {run.taken_s - run.first_s:.1f} s"
        if sid in FRONT_SENSORS and run.odometer is not None and kind != FAR:
            drove = run.last_odometer - run.odometer
            # too near says only that the surface is nearer than the minimum:
            # backing away more than the minimum (and the limit) must end it
            if (drove < -(v + self._limit)) if kind == NEAR else abs(drove) > self._limit:
                way = "toward" if drove > 0 else "away from"
                return f"{held} while the drive moved {abs(drove) * 1000:.0f} mm {way} the riser"
        return None if partner is None else f"{held} while {partner}"

    def _partner(self, sid: SensorId, run: _Run, seen: dict[SensorId, SensorReading]
                 ) -> str | None:
        """Follow the partner's reading on this tick; what it did, if it
        moved as this one's surface must have (see the module docstring)."""
        partner = _PARTNER[sid]
        value = self._value(partner, seen.get(partner))
        last, run.partner_last = run.partner_last, value
        if value is None:
            run.partner = run.evidence = None
            return None
        if last is None or last[1] != value[1] or abs(value[0] - last[0]) > PARTNER_JUMP_M:
            if self._now > run.settled_s:  # onto another surface
                run.jumped_from = last
            run.settled_s = self._now + self._settle[partner]
        start = run.partner
        if start is None or self._now <= run.settled_s or value[1] != OK or run.value[1] == FAR:
            # only a distance the partner reads is a move; a clamp is not one
            # (a cone that partly sees a riser's top reads "nothing" or "too
            # near" as it likes: lowering segment 1 the reference robot's SFR
            # read too near, SFL nothing, over 48 turns), nor is a run of
            # "nothing" judged by one
            run.partner, run.evidence = value, None
            return None
        back = sid in BACK_SENSORS
        # under way: moving smoothly (half the margin), or jumped from where the two agreed
        moving = value[1] == start[1] == run.value[1] == OK and abs(value[0] - start[0]) > \
            self._margin(run.value, value, back) / 2.0
        jumped = run.jumped_from is not None and self._agree(run.value, run.jumped_from, back)
        if not (moving or jumped):
            run.evidence = None
            return None
        if run.evidence is None:
            run.evidence = self._travel
        if self._agree(run.value, value, back):
            return None
        wheels = run.last_motion[0] - run.evidence[0]
        lifts = run.last_motion[1] - run.evidence[1]
        if lifts > PARTNER_LIFT_M:
            moved = f"the lifts moved {lifts * 1000:.0f} mm"
        elif wheels > PARTNER_DRIVE_M:
            moved = f"the wheels {wheels * 1000:.0f} mm"
        else:
            return None
        was = run.jumped_from if jumped and run.jumped_from is not None else start
        return (f"{partner.value}'s reading went from {_say(was)} to {_say(value)} and "
                f"{moved} since")

    def _margin(self, mine: Value, other: Value, back: bool) -> float:
        """How far two values of a pair may stand apart and still agree."""
        margin = pair_tolerance(self._cfg, max(mine[0], other[0]), back=back)
        return margin if mine[1] == OK else max(margin, NEAR_JUMP_M)

    def _agree(self, mine: Value, other: Value, back: bool) -> bool:
        """Whether the partner's value ``other`` fits this one's: the same
        distance within the margin, or the same clamp ("too near" also fits
        a distance not NEAR_JUMP_M beyond it: the pair may differ below it)."""
        if mine[1] == FAR or other[1] == FAR:
            return mine[1] == other[1]
        if mine[1] == NEAR or other[1] == NEAR:
            near, far = (mine, other) if mine[1] == NEAR else (other, mine)
            return far[0] <= near[0] + max(pair_tolerance(self._cfg, far[0], back=back),
                                          NEAR_JUMP_M)
        return abs(other[0] - mine[0]) <= self._margin(mine, other, back)


def _say(value: Value) -> str:
    """A value in words."""
    d, kind = value
    return f"{d:.3f} m" if kind == OK else "too near" if kind == NEAR else "nothing"
