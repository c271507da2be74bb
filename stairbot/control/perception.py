"""Perception: what the algorithm sees of the distance sensors.

Every snapshot passes through :class:`Perception` before any phase sees it.
Per sensor it works on *measurements*, not ticks: a sensor slower than the
tick repeats its last value, and the board says how old it is
(``SensorReading.age_s``), so a repeated value counts once.  Then:

* **kind**: each measurement is OK, NEAR (out of range, too near), FAR (out of
  range, nothing within it) or ERROR.  The kind the algorithm sees changes
  only when CONFIRM measurements in a row agree on the new one (hysteresis):
  a dropout, a spike or a lone "out of range" decides nothing.
* **distance**: the median of the last WINDOW OK measurements (5) -- no
  two outliers among them move it.  The front sensors look
  along the drive: each older measurement is carried forward by the distance
  the wheels have driven since it was taken, so the median of a moving robot
  is today's distance.
* **staleness**: a sensor whose newest measurement is older than its
  datasheet's latency plus STALE_PERIODS periods (a frozen sensor, a board
  that stopped updating it) reads as ERROR: it is not used.
  :meth:`Perception.why` says which.

Decisions that compare two sensors ("equal", the standing rule) use
tolerances derived from the sensors' stated noise at the distance measured
(:mod:`stairbot.inputs.sensor_specs`, ``[sensors]`` in the robot config), not from a
guess.  Pure Python, on the controller's clock (the snapshots' times),
deterministic.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterable
from enum import IntEnum

from stairbot.hardware import (
    BACK_SENSORS,
    FRONT_SENSORS,
    SIDE_SENSORS,
    WHEEL_MOTORS,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
)
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.sensor_specs import SensorSpec

WINDOW = 5
"""Measurements a sensor's median spans, whatever its period.  Five, not
three: two stray measurements in a row pass a median of three -- for an
HC-SR04 pair (1 % outliers, a measurement every 60 ms) about three times a
run, for a VL53L1X pair often enough to pause the standing rule -- and set
reading drives' targets centimetres off."""
CONFIRM = 3
"""Measurements in a row that must agree before the kind seen changes."""
STALE_PERIODS = 3.0
"""A measurement older than latency + this many periods (+ a tick) is stale."""
SIGMAS = 4.0
"""A difference counts as real when it exceeds this many of its own sigmas."""
MEDIAN_EFFICIENCY = 1.25
"""The median of n normal samples has about 1.25 times the sigma of their mean."""
ODOMETER_HISTORY = 32
"""Ticks of odometer kept to place an old measurement (0.64 s at 20 ms)."""


class Kind(IntEnum):
    OK = 0
    NEAR = 1
    FAR = 2
    ERROR = 3


# bound once: an enum's member costs a slow attribute look-up, every sensor every tick
_KIND_OK, _KIND_ERROR = Kind.OK, Kind.ERROR
_STATUS_OK = SensorStatus.OK


def measurement_period(cfg: RobotConfig, back: bool) -> float:
    """How often the pair gives a new measurement: its period, or every tick."""
    return _period(cfg, cfg.sensors.spec(back))


def window(cfg: RobotConfig, back: bool) -> int:
    """Measurements the pair's median spans (WINDOW, for every pair)."""
    return WINDOW


def max_age(cfg: RobotConfig, back: bool) -> float:
    """The oldest a measurement of the pair may be and still be used."""
    return _max_age(cfg, cfg.sensors.spec(back))


def settle_s(cfg: RobotConfig, back: bool = False) -> float:
    """How long the pair's filtered readings take to stand for where the robot
    stands now, once it stops: its latency and a full window of measurements.
    Measurements to average standing still start after it."""
    return _settle_s(cfg, cfg.sensors.spec(back))


def side_settle_s(cfg: RobotConfig) -> float:
    """:func:`settle_s` of the side pair (``[sensors] side_model``)."""
    return _settle_s(cfg, cfg.sensors.side_spec())


def _period(cfg: RobotConfig, spec: SensorSpec) -> float:
    return max(spec.period_s, cfg.algorithm.tick)


def _max_age(cfg: RobotConfig, spec: SensorSpec) -> float:
    return spec.latency_s + STALE_PERIODS * _period(cfg, spec) + cfg.algorithm.tick


def _settle_s(cfg: RobotConfig, spec: SensorSpec) -> float:
    return spec.latency_s + WINDOW * _period(cfg, spec)


def median_sigma(cfg: RobotConfig, back: bool, distance_m: float) -> float:
    """Sigma of the pair's filtered reading at ``distance_m``."""
    k = _pair(cfg, back)
    return _median_sigma(k, k.sigma(distance_m))


def pair_tolerance(cfg: RobotConfig, distance_m: float, smoothing: float = 1.0,
                   back: bool = False) -> float:
    """How far two filtered readings of one surface ``distance_m`` away may
    differ and still be "equal": equal_tolerance, or SIGMAS sigmas of their
    difference if the sensors are noisier than that allows.  ``smoothing`` is
    the weight of an exponential smoothing applied each tick on top (1.0:
    none); it averages fewer independent values when the sensor is slower
    than the tick."""
    k = _pair(cfg, back)
    return _pair_tolerance(k, k.sigma(distance_m), smoothing)


def standing_tolerance(cfg: RobotConfig, distance_m: float, smoothing: float = 1.0,
                       back: bool = False) -> float:
    """How far the pair may differ while the robot drives or lifts before the
    standing rule stops it: what calibration may have left
    (:func:`square_tolerance`), plus SIGMAS sigmas of the (smoothed) difference."""
    k = _pair(cfg, back)
    sigma = k.sigma(distance_m)
    # the standing rule asks every tick; the answer depends on the sigma alone
    known = k.standing
    tolerance = known.get((sigma, smoothing))
    if tolerance is None:
        if len(known) >= _KNOWN_SIGMAS:
            known.clear()
        tolerance = known[sigma, smoothing] = (_square_tolerance(k, sigma)
                                               + _pair_tolerance(k, sigma, smoothing))
    return tolerance


MAX_STILL_S = 5.0
"""The longest calibration stands still to square up (a very noisy sensor
squares up as well as this allows, and the standing rule allows for it)."""


def still_samples(cfg: RobotConfig, distance_m: float, back: bool = False) -> int:
    """Ticks of standing still whose mean pair difference is known to within
    equal_tolerance (:func:`still_tolerance`), at most MAX_STILL_S of them:
    calibration squares up to that yaw."""
    k = _pair(cfg, back)
    return _still_samples(k, k.sigma(distance_m))


def square_tolerance(cfg: RobotConfig, distance_m: float, back: bool = False) -> float:
    """The pair difference calibration leaves at most when it squares up:
    equal_tolerance, or more for a sensor too noisy to get there in MAX_STILL_S."""
    k = _pair(cfg, back)
    return _square_tolerance(k, k.sigma(distance_m))


def quiet_range_m(cfg: RobotConfig) -> float:
    """Farthest reading from which the front pair squares up to
    equal_tolerance (:func:`square_tolerance`): farther, its stated noise
    allows only a looser square in MAX_STILL_S (a Sharp's sigma is 1 mm + 2 %
    of the distance).  Infinite when the pair does it anywhere short of
    LENGTH_OF_INFINITY."""
    k = _pair(cfg, False)
    if k.quiet is None:
        equal = cfg.algorithm.equal_tolerance + 1e-12
        lo, hi = cfg.sensors.range(False)[0], cfg.LENGTH_OF_INFINITY
        if _square_tolerance(k, k.sigma(hi)) <= equal:
            k.quiet = math.inf
        elif _square_tolerance(k, k.sigma(lo)) > equal:
            k.quiet = lo
        else:
            for _ in range(40):  # the sigma grows with the distance: bisect to 0.1 mm
                mid = (lo + hi) / 2.0
                lo, hi = (mid, hi) if _square_tolerance(k, k.sigma(mid)) <= equal else (lo, mid)
                if hi - lo < 1e-4:
                    break
            k.quiet = lo
    return k.quiet


def still_tolerance(cfg: RobotConfig, samples: int, distance_m: float,
                    back: bool = False) -> float:
    """Like :func:`pair_tolerance`, for the mean of ``samples`` ticks' filtered
    differences taken standing still."""
    k = _pair(cfg, back)
    return _still_tolerance(k, samples, k.sigma(distance_m))


# -- the same, from a pair's figures and the stated sigma at the distance ---------------
class _Pair:
    """What the tolerances of one pair need of the config, looked up once."""

    __slots__ = ("spec", "noise", "equal", "repeats", "sqrt_window", "max_still", "standing",
                 "quiet")

    def __init__(self, cfg: RobotConfig, back: bool) -> None:
        self.spec = cfg.sensors.spec(back)
        self.noise = cfg.sensors.noise
        self.equal = cfg.algorithm.equal_tolerance
        self.repeats = measurement_period(cfg, back) / cfg.algorithm.tick
        """Ticks per measurement (at least 1)."""
        self.sqrt_window = math.sqrt(window(cfg, back))
        self.max_still = round(MAX_STILL_S / cfg.algorithm.tick)
        self.standing: dict[tuple[float, float], float] = {}
        """standing_tolerance by (sigma, smoothing)."""
        self.quiet: float | None = None
        """quiet_range_m, once asked."""

    def sigma(self, distance_m: float) -> float:
        """The stated sigma of one reading at ``distance_m`` (Sensors.sigma)."""
        return self.spec.sigma(distance_m, self.noise)


_KNOWN_SIGMAS = 256
"""standing_tolerance remembers at most this many answers per pair (a sensor
whose noise grows with the distance gives a new sigma at most ticks)."""

_derived: tuple[RobotConfig, tuple[_Pair, _Pair]] | None = None
"""The last config asked about and its pairs (front, back): a run asks about
one config, every tick.  A config is frozen, so its pairs never change."""


def _pair(cfg: RobotConfig, back: bool) -> _Pair:
    global _derived
    derived = _derived
    if derived is None or derived[0] is not cfg:
        derived = _derived = (cfg, (_Pair(cfg, False), _Pair(cfg, True)))
    return derived[1][1 if back else 0]


def _median_sigma(k: _Pair, sigma: float) -> float:
    return MEDIAN_EFFICIENCY * sigma / k.sqrt_window


def _pair_tolerance(k: _Pair, sigma: float, smoothing: float) -> float:
    sigma_diff = math.sqrt(2.0) * _median_sigma(k, sigma)
    sigma_diff *= math.sqrt(min(1.0, k.repeats * smoothing / (2.0 - smoothing)))
    return max(k.equal, SIGMAS * sigma_diff)


def _still_samples(k: _Pair, sigma: float) -> int:
    one = SIGMAS * _still_sigma(sigma, 1.0)
    independent = (one / k.equal) ** 2
    return max(1, min(k.max_still, math.ceil(independent * k.repeats)))


def _square_tolerance(k: _Pair, sigma: float) -> float:
    return _still_tolerance(k, _still_samples(k, sigma), sigma)


def _still_tolerance(k: _Pair, samples: int, sigma: float) -> float:
    sigma_diff = _still_sigma(sigma, max(1.0, samples / k.repeats))
    return max(k.equal, SIGMAS * sigma_diff)


def _still_sigma(sigma: float, independent: float) -> float:
    """Sigma of the mean of ``independent`` filtered pair differences."""
    return math.sqrt(2.0) * MEDIAN_EFFICIENCY * sigma / math.sqrt(independent)


class _Track:
    """One sensor's recent measurements and the kind seen."""

    __slots__ = ("front", "max_age", "midpoint", "ok_keys", "newest", "taken_s", "kind",
                 "run_kind", "run", "last_of_kind", "seen_ok")

    def __init__(self, front: bool, window: int, max_age: float, midpoint: float) -> None:
        self.front = front
        self.max_age = max_age
        self.midpoint = midpoint
        self.ok_keys: deque[float] = deque(maxlen=window)
        """The last OK measurements' distances, plus (front) the odometer when
        each was taken; emptied when the kind seen leaves OK."""
        self.newest: SensorReading | None = None
        self.taken_s = -math.inf
        self.kind: Kind | None = None
        self.run_kind: Kind | None = None
        self.run = 0
        self.last_of_kind: dict[Kind, SensorReading] = {}
        self.seen_ok: SensorReading | None = None  # the last OK one of age 0 given out


class Perception:
    """Filters snapshots (see the module docstring).  One per controller."""

    def __init__(self, cfg: RobotConfig) -> None:
        self._metres_per_turn = cfg.wheel_circumference / len(WHEEL_MOTORS)
        self._wheels = WHEEL_MOTORS[0], WHEEL_MOTORS[1], WHEEL_MOTORS[2], WHEEL_MOTORS[3]
        self._tracks: dict[SensorId, _Track] = {}
        for back, ids in ((False, FRONT_SENSORS), (True, BACK_SENSORS)):
            lo, hi = cfg.sensors.range(back)
            for sid in ids:
                self._tracks[sid] = _Track(not back, window(cfg, back), max_age(cfg, back),
                                           (lo + hi) / 2.0)
        s = cfg.sensors
        if s.has_side_pair:
            # the side pair looks across the robot's path: driving does not move
            # what it sees, so its medians are of the readings themselves (as
            # the back pair's)
            age = _max_age(cfg, s.side_spec())
            lo, hi = s.side_range()
            for sid in SIDE_SENSORS:
                self._tracks[sid] = _Track(False, WINDOW, age, (lo + hi) / 2.0)
        self._odometer: deque[tuple[float, float]] = deque(maxlen=ODOMETER_HISTORY)
        self._why: dict[SensorId, str] = {}

    def see(self, snap: Snapshot) -> Snapshot:
        """The snapshot as the algorithm should see it."""
        turns = snap.motors
        w0, w1, w2, w3 = self._wheels
        odometer = (turns[w0].turns + turns[w1].turns + turns[w2].turns + turns[w3].turns) \
            * self._metres_per_turn
        now = snap.time_s
        self._odometer.append((now, odometer))
        sensors: dict[SensorId, SensorReading] = {}
        tracks = self._tracks
        for sid, reading in snap.sensors.items():
            track = tracks[sid]
            age = reading.age_s
            if age <= 0.0:  # measured now (a sensor as fast as the tick)
                if reading.status is _STATUS_OK:
                    d = reading.distance_m
                    if d - d != 0.0:  # inf or NaN: not a measurement but a broken board
                        sensors[sid] = reading
                        continue
                    if track.kind is _KIND_OK and track.run_kind is _KIND_OK:
                        # the common case, kept short: another OK measurement
                        track.newest, track.taken_s = reading, now
                        track.run += 1
                        keys = track.ok_keys
                        keys.append(d + odometer if track.front else d)
                        m = _median(keys) - odometer if track.front else _median(keys)
                        # immutable, and a new one costs: reuse an equal one (0.0 may be -0.0)
                        seen = track.seen_ok
                        if seen is None or seen.distance_m != m or m == 0.0:
                            seen = track.seen_ok = SensorReading(m)
                        sensors[sid] = seen
                        continue
                self._measured(track, reading, now, odometer)
            elif now - age > track.taken_s + 1e-9:
                self._measured(track, reading, now - age, self._odometer_at(now - age))
            sensors[sid] = self._verdict(sid, track, now, odometer)
        return Snapshot(snap.time_s, sensors, snap.motors, snap.health, snap.imu)

    def why(self, sensor: SensorId) -> str | None:
        """Why the sensor reads as ERROR now (stale, errors), or None."""
        return self._why.get(sensor)

    # -- per measurement ----------------------------------------------------------------
    def _measured(self, track: _Track, reading: SensorReading, taken: float,
                  odometer: float) -> None:
        if reading.status is SensorStatus.OK:
            if not math.isfinite(reading.distance_m):
                reading = SensorReading(reading.distance_m, SensorStatus.ERROR, reading.age_s)
                kind = Kind.ERROR
            else:
                kind = Kind.OK
                d = reading.distance_m
                track.ok_keys.append(d + odometer if track.front else d)
        elif reading.status is SensorStatus.OUT_OF_RANGE:
            kind = Kind.NEAR if reading.distance_m < track.midpoint else Kind.FAR
        else:
            kind = Kind.ERROR
        track.newest, track.taken_s = reading, taken
        track.last_of_kind[kind] = reading
        if kind is track.run_kind:
            track.run += 1
        else:
            track.run_kind, track.run = kind, 1
        if track.kind is None or (kind is not track.kind and track.run >= CONFIRM):
            if track.kind is Kind.OK:
                # a fresh median when it comes back
                track.ok_keys.clear()
            track.kind = kind

    def _odometer_at(self, t: float) -> float:
        """The odometer at time ``t`` (linear between ticks; the oldest kept if older)."""
        later: tuple[float, float] | None = None
        for at, odo in reversed(self._odometer):
            if at <= t:
                if later is None or later[0] == at:
                    return odo
                return odo + (later[1] - odo) * (t - at) / (later[0] - at)
            later = (at, odo)
        return self._odometer[0][1]

    def _verdict(self, sid: SensorId, track: _Track, now: float, odometer: float
                 ) -> SensorReading:
        newest = track.newest
        assert newest is not None and track.kind is not None
        age = now - track.taken_s
        if age > track.max_age:
            self._why[sid] = (f"stale: its newest measurement is {age:.2f} s old "
                              f"(at most {track.max_age:.2f} s)")
            return SensorReading(newest.distance_m, SensorStatus.ERROR, age)
        kind = track.kind
        if kind is _KIND_OK:
            if track.ok_keys:
                m = _median(track.ok_keys)
                self._why.pop(sid, None)
                return SensorReading(m - odometer if track.front else m, _STATUS_OK, age)
            self._why[sid] = "no valid measurement among its last ones"
            return SensorReading(newest.distance_m, SensorStatus.ERROR, age)
        if kind is _KIND_ERROR:
            self._why[sid] = f"{CONFIRM} measurements in a row report an error"
            return SensorReading(newest.distance_m, SensorStatus.ERROR, age)
        self._why.pop(sid, None)
        held = track.last_of_kind[kind]
        return SensorReading(held.distance_m, SensorStatus.OUT_OF_RANGE, age)


def _median(values: Iterable[float]) -> float:
    """statistics.median, without its generality (every sensor, every tick)."""
    s = sorted(values)
    n = len(s)
    half = n // 2
    return s[half] if n % 2 else (s[half - 1] + s[half]) / 2
