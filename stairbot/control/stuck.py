"""Stuck distance sensors: fresh measurements whose value no longer changes
where the robot's own motion says it must have (issue 33).

A sensor whose ADC or firmware froze repeats its last distance as a new
measurement: its age is that of a working sensor, so staleness does not see
it.  What gives it away is a value that stays the same (the very value, after
the sensor's rounding) for REPEATS measurements in a row or more while the
robot moved what it looks at:

* **the drive** (SFR, SFL, on a riser or a wall: LEVEL_DEG): the front pair
  looks along the drive, and driving d towards (or away from) any flat
  surface a beam meets shortens (lengthens) that beam by d; a cone's mix, or
  a nearest echo, moves with it.  So a value that stays the same while the
  odometer moved more than :func:`drive_limit` (STUCK_MOVE_M, or RESOLUTIONS
  of the sensor's rounding if more: rounding hides less than one step) is
  stuck.  The odometer here counts what every wheel turned alike (the least
  of the four, when all turn one way): wheels that do not turn alike (one
  jammed, the robot against something unseen) move the robot by less than
  their mean, or not at all, and the stall watch is theirs.  A value "too
  near" says only that the surface is nearer than the minimum: backing away
  more than the minimum (and the limit) must end it.  One that does not
  says the sensor reads too near -- stuck, or biased short (a front sensor
  2 cm short reads under the minimum at a riser 4 cm away, and stays there
  as the robot backs 4 cm): the host cannot tell which, and says only that.
* **the lift, by the partner** (SBR, SBL): the back pair looks down from
  segment 3, so a drive along a tread does not change what it reads, and
  MTB moves segment 3 (and the pair) when segment 3 hangs, or segment 2
  when segment 3 stands, which perception does not know.  The partner
  tells: when its filtered reading moves smoothly with MTB's travel (at
  least half of it, at most all of it and the pair's noise,
  :func:`~stairbot.control.tolerances.pair_tolerance`), away from this
  one's value by more than that noise, and MTB turns on PARTNER_LIFT_M more,
  segment 3 moved, and this one should have followed.  A partner that jumps
  (an edge, its own fault's onset) or moves without MTB (a bias creeping in)
  says nothing of this one: which of the two is wrong is then not known.

A robot standing still, or turning on the spot with a noiseless sensor,
reads the same value for as long as it likes: neither rule fires, since
nothing moved.  A sensor reading "nothing within range" or an error is not
judged (it has no value to be stuck at); nor is the front pair by its
partner (a lift does not move what it reads; a partner whose reading moves
and this one's not may as well be the one that is wrong).  Judged stuck, a
sensor reads as ERROR (:meth:`StuckWatch.judge`), with why, until its value
changes: a
sensor the phase needs then stands the robot and, if it stays so, is lost
(the limp home of :mod:`~stairbot.control.algorithm.limp`).  The side pair
is not judged (nothing limps home on it).  The algorithm may judge one
stuck too (:meth:`StuckWatch.distrust`), on what only it knows: the
calibration's turn, descent 1's square heading.
"""

from __future__ import annotations

import math
from collections import deque

from stairbot.control.timeline import value_at
from stairbot.control.tolerances import pair_tolerance, settle_s
from stairbot.hardware import (
    BACK_SENSORS,
    FRONT_SENSORS,
    WHEEL_MOTORS,
    Imu,
    MotorId,
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
"""Within this pitch of segment 2 (the IMU) the front beams meet risers and
walls, which the drive moves them along.  Pitched nose down, a beam may
meet the tread ahead, whose distance the robot driving along the treads does
not change (the ideal robot, noiseless, pitched 3.4 degrees nose down in
ascent 6 onto the top step: SFL read 0.493 m, the landing 3 cm below its
beam, while the drive moved 12 mm): then the rule holds only for a value
nearer than FLOOR_SHARE of the distance at which the lowest ray would meet
the floor the robot stands on (:meth:`StuckWatch._floor_m`).  Without an
IMU the pitch is not known: the rule does not hold."""
FLOOR_SHARE = 0.8
HELD_CHANCE = 1e-5
"""The algorithm's judgment (:meth:`StuckWatch.distrust`) of a sensor holding
a distance takes as many measurements in a row (REPEATS at least) as make
this the chance that one that is not stuck repeats its value so often
standing on one surface (:func:`held_repeats`)."""
PARTNER_JUMP_M = 0.02
"""A partner's filtered reading that moves more than this from one tick to
the next jumped (onto another surface, or its own fault began): its moves
count afresh once its median has settled
(:func:`~stairbot.control.tolerances.settle_s`)."""
PARTNER_LIFT_M = 0.004
"""MTB travel after the partner was seen to move with it that this one must
have followed: small, and within what the standing rule allows the back
pair in descent 2 beyond the pair's noise (judged later, the rule stops the
robot first, and the run ends there)."""
HISTORY = 32
"""Ticks of odometer and MTB travel kept to place a measurement the board
publishes late (0.64 s at 20 ms, as perception's odometer)."""

_PARTNER = {SensorId.SFR: SensorId.SFL, SensorId.SFL: SensorId.SFR,
            SensorId.SBR: SensorId.SBL, SensorId.SBL: SensorId.SBR}
_OK, _OUT = SensorStatus.OK, SensorStatus.OUT_OF_RANGE
_MTB = MotorId.MTB
OK, NEAR, FAR = 0, 1, 2
"""What a value is: a distance, the "too near" clamp, the "nothing within
range" clamp."""

Value = tuple[float, int]
"""A reading as this watch takes it: the distance and its kind."""


def held_repeats(cfg: RobotConfig, back: bool, distance_m: float) -> int:
    """Measurements of one distance in a row that a sensor that is not
    stuck gives with a chance of HELD_CHANCE, the surface not moving: two
    readings of a stated sigma s rounded to steps r are equal about
    r / (2 sqrt(pi) s) of the time (for s well over r; at most 0.99 here, so
    a noiseless sensor is never judged so).  A VL53L0X 0.04 m above a tread
    (s 3.8 mm in 1 mm steps): REPEATS; an HC-SR04 (s 2.1 mm in 3 mm steps):
    14."""
    spec = cfg.sensors.spec(back)
    resolution = spec.resolution or cfg.sensors.resolution
    sigma = spec.sigma(distance_m, cfg.sensors.noise)
    same = 0.99 if sigma <= 0.0 else min(0.99, resolution / (2.0 * math.sqrt(math.pi) * sigma))
    return max(REPEATS, 1 + math.ceil(math.log(HELD_CHANCE) / math.log(same)))


def drive_limit(cfg: RobotConfig) -> float:
    """How far the drive may move while a front reading stays the same."""
    resolution = cfg.sensors.spec(False).resolution
    if resolution is None:
        resolution = cfg.sensors.resolution
    return max(STUCK_MOVE_M, RESOLUTIONS * resolution)


class _Run:
    """One sensor's current run of measurements of one value, and what its
    partner did meanwhile.  A front sensor's run follows the drive's
    odometer (its MTB figures stay 0), a back sensor's MTB's travel (its
    odometer figures stay 0, and None)."""

    __slots__ = ("value", "count", "first_s", "taken_s", "odometer", "last_odometer",
                 "last_lift", "partner", "partner_last", "settled_s", "lift_from", "evidence",
                 "why")

    def __init__(self, value: Value, taken_s: float, odometer: float, clear: bool,
                 lift: float, settled_s: float) -> None:
        self.value = value
        self.count = 1
        self.first_s = self.taken_s = taken_s
        self.odometer: float | None = odometer if clear else None
        """The odometer from which the drive counts: at the run's first
        measurement that was a riser's or a wall's since the last that may
        not have been (None: may not be)."""
        self.last_odometer = odometer
        """The odometer at the latest measurement."""
        self.last_lift = lift
        """MTB's travel (any direction) at the latest measurement."""
        self.partner: float | None = None
        """The partner's reading its moves count from (None: none yet)."""
        self.partner_last: Value | None = None
        """... its value on the last tick."""
        self.settled_s = settled_s
        """Until then the partner's median may be settling after a jump."""
        self.lift_from = lift
        """MTB's travel from which the partner's move counts."""
        self.evidence: float | None = None
        """MTB's travel when the partner was first seen to move with it."""
        self.why: str | None = None
        """Judged stuck: why."""


class StuckWatch:
    """Judges SFR, SFL, SBR and SBL stuck (see the module docstring).  One per
    :class:`~stairbot.control.perception.Perception`, on its clock."""

    def __init__(self, cfg: RobotConfig) -> None:
        self._cfg = cfg
        self._wheel_m = cfg.wheel_circumference
        self._lift_m = cfg.motors.lift_travel_per_turn
        self._limit = drive_limit(cfg)
        self._runs: dict[SensorId, _Run | None] = dict.fromkeys(FRONT_SENSORS + BACK_SENSORS)
        self._front = frozenset(FRONT_SENSORS)
        self._midpoint = {sid: sum(cfg.sensors.range(sid in BACK_SENSORS)) / 2.0
                          for sid in self._runs}
        self._settle = settle_s(cfg, back=True)
        self._now = 0.0
        self._taken: dict[SensorId, float] = {}
        self._turns: tuple[float, ...] | None = None
        self._odometer = 0.0
        self._lift = 0.0
        self._imu: Imu | None = None
        """This tick's IMU reading (its pitch says what the front pair looks at)."""
        s = cfg.sensors
        fov = s.spec(back=False).fov_deg if s.front_fov_deg is None else s.front_fov_deg
        self._lowest_deg = s.front_tilt_deg - fov / 2.0
        self._beam_m = s.front_height
        self._odometers: deque[tuple[float, float]] = deque(maxlen=HISTORY)
        self._lifts: deque[tuple[float, float]] = deque(maxlen=HISTORY)

    def judge(self, snap: Snapshot, seen: dict[SensorId, SensorReading],
              why: dict[SensorId, str]) -> None:
        """Follow ``snap``'s raw measurements; in ``seen`` (perception's
        filtered readings) make each sensor judged stuck read as ERROR, and
        say why in ``why``."""
        now = self._now = snap.time_s
        self._moved(snap, now)
        sensors, taken_at = snap.sensors, self._taken
        for sid, run in self._runs.items():
            raw = sensors.get(sid)
            if raw is None:
                continue
            taken = now - raw.age_s
            if taken > taken_at.get(sid, -math.inf) + 1e-9:  # a new measurement
                taken_at[sid] = taken
                run = self._measured(sid, run, raw, taken)
            if run is None:
                continue
            # the partner is followed every tick; a run is judged from REPEATS
            # measurements on, and once judged it stays so while the value
            # holds (the figures as they stand)
            lifted = None if sid in self._front else self._partner(sid, run, seen)
            if run.count >= REPEATS:
                run.why = self._stuck(sid, run, lifted) or run.why
            if run.why is not None:
                held = seen.get(sid)
                age = raw.age_s if held is None else held.age_s
                seen[sid] = SensorReading(run.value[0], SensorStatus.ERROR, age)
                why[sid] = run.why

    def distrust(self, sid: SensorId, why: str) -> bool:
        """Judge ``sid`` stuck for ``why``, a reason the algorithm found (a
        value held through a turn its partner saw, a crossing it missed), if
        its measurements say so too: its value held REPEATS measurements in
        a row, a distance :func:`held_repeats` (a noiseless sensor holds a
        value by right).
        As the rules' own judgment, it holds while the value does.  Whether
        it was judged: the algorithm's reason alone may as well be its
        partner's fault (a partner reading long reads a drop early)."""
        run = self._runs.get(sid)
        if run is None or run.why is not None or run.count < REPEATS:
            return False
        value, kind = run.value
        if kind == OK and run.count < held_repeats(self._cfg, sid in BACK_SENSORS, value):
            return False
        run.why = why
        return True

    def _moved(self, snap: Snapshot, now: float) -> None:
        """Add what every wheel drove alike this tick to the odometer, and
        MTB's turns, any direction, to its travel."""
        motors = snap.motors
        w0, w1, w2, w3 = WHEEL_MOTORS
        turns = (motors[w0].turns, motors[w1].turns, motors[w2].turns, motors[w3].turns,
                 motors[_MTB].turns)
        last = self._turns
        if last is not None:
            d0, d1, d2, d3 = (turns[0] - last[0], turns[1] - last[1], turns[2] - last[2],
                              turns[3] - last[3])
            lift = abs(turns[4] - last[4]) * self._lift_m
            least = min(d0, d1, d2, d3)
            if lift == lift and least == least:  # not a number: no move here
                self._lift += lift
                most = max(d0, d1, d2, d3)
                if least > 0.0 or most < 0.0:
                    alike = least if d0 > 0.0 else most
                    self._odometer += alike * self._wheel_m
        self._turns = turns
        self._imu = snap.imu
        self._odometers.append((now, self._odometer))
        self._lifts.append((now, self._lift))

    def _clear_m(self) -> float:
        """A front value nearer than this is a riser's or a wall's, at this
        tick's pitch (-1: none is, the pitch not known)."""
        imu = self._imu
        return -1.0 if imu is None else self._floor_m(imu.pitch_deg)

    def _floor_m(self, pitch_deg: float) -> float:
        """How near a front value must be to be a riser's or a wall's, at
        segment 2's pitch: level, any; pitched, nearer than FLOOR_SHARE of
        where the lowest ray meets the floor (infinite if no ray looks down)."""
        if abs(pitch_deg) <= LEVEL_DEG:
            return math.inf
        down = -(pitch_deg + self._lowest_deg)
        if down <= 0.0:
            return math.inf
        return FLOOR_SHARE * self._beam_m / math.sin(math.radians(min(down, 90.0)))

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
        if sid in self._front:  # judged by the drive (the module docstring)
            odometer, lift = value_at(self._odometers, taken), 0.0
            clear = value[0] < self._clear_m()  # a riser's or a wall's: the drive moves it
        else:  # judged by the partner, as MTB moves segment 3
            odometer, lift, clear = 0.0, value_at(self._lifts, taken), False
        if run is not None and value == run.value:
            run.taken_s, run.last_odometer, run.last_lift = taken, odometer, lift
            if not clear:
                run.odometer = None
            elif run.odometer is None:
                run.odometer = odometer
            run.count += 1
            return run
        # the partner's median may be settling on a surface it jumped onto
        # just before: its moves count from when it has
        run = _Run(value, taken, odometer, clear, lift, self._now + self._settle)
        self._runs[sid] = run
        return run

    def _stuck(self, sid: SensorId, run: _Run, lifted: str | None) -> str | None:
        """Why the run (REPEATS measurements or more) says the sensor is
        stuck, or None; ``lifted``: what the partner did, if it moved with
        MTB as this one should have (:meth:`_partner`)."""
        v, kind = run.value
        if sid in self._front and run.odometer is not None and kind != FAR:
            drove = run.last_odometer - run.odometer
            # too near says only that the surface is nearer than the minimum:
            # backing away more than the minimum (and the limit) must end it.
            # Still too near, the sensor reads wrong: stuck, or reading short
            # (a bias), which the host cannot tell apart -- so it says which
            if kind == NEAR and drove < -(v + self._limit):
                return (f"reads too near (under {v:.3f} m) after the drive moved "
                        f"{-drove * 1000:.0f} mm away from the riser")
            if kind == OK and abs(drove) > self._limit:
                way = "toward" if drove > 0 else "away from"
                return (f"{self._held(run)} while the drive moved {abs(drove) * 1000:.0f} mm "
                        f"{way} the riser")
        return None if lifted is None else f"{self._held(run)} while {lifted}"

    @staticmethod
    def _held(run: _Run) -> str:
        """A run of one distance, judged stuck: its value and how long it held."""
        return f"stuck at {run.value[0]:.3f} m for {run.taken_s - run.first_s:.1f} s"

    def _partner(self, sid: SensorId, run: _Run, seen: dict[SensorId, SensorReading]
                 ) -> str | None:
        """Follow a back sensor's partner on this tick; what it did, if it
        moved with MTB as this one should have (see the module docstring)."""
        partner = _PARTNER[sid]
        value = self._value(partner, seen.get(partner))
        last, run.partner_last = run.partner_last, value
        lift = self._lift
        if value is None or value[1] != OK or run.value[1] != OK:
            run.partner = run.evidence = None
            return None
        now = value[0]
        if last is None or last[1] != OK or abs(now - last[0]) > PARTNER_JUMP_M:
            run.settled_s = self._now + self._settle
        start = run.partner
        if start is None or self._now <= run.settled_s:
            run.partner, run.lift_from, run.evidence = now, lift, None
            return None
        changed = now - start
        margin = pair_tolerance(self._cfg, max(now, run.value[0]), back=True)
        if abs(changed) <= margin / 2.0:
            # not moving (yet): what MTB turned meanwhile moved segment 2, not the pair
            run.lift_from, run.evidence = lift - abs(changed), None
            return None
        lifted = lift - run.lift_from
        if not lifted / 2.0 <= abs(changed) <= lifted + margin:
            run.evidence = None  # not MTB's doing: which of the two is wrong is not known
            return None
        if run.evidence is None:
            run.evidence = lift
        if abs(changed) <= margin or abs(now - run.value[0]) <= margin:
            return None
        if run.last_lift - run.evidence <= PARTNER_LIFT_M:
            return None
        return (f"{partner.value}'s reading went from {start:.3f} m to {now:.3f} m as MTB "
                f"moved segment 3 {lifted * 1000:.0f} mm")
