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
  two outliers among them move it.  While the kind seen is not OK, only the
  current run of OK measurements is kept: a lone OK one among out-of-range
  ones is a stray, and must not be in the median when OK comes back.  The front sensors look
  along the drive: each older measurement is carried forward by the distance
  the wheels have driven since it was taken, so the median of a moving robot
  is today's distance.
* **staleness**: a sensor whose newest measurement is older than its
  datasheet's latency plus STALE_PERIODS periods (a frozen sensor, a board
  that stopped updating it) reads as ERROR: it is not used.
* **stuck**: a sensor whose fresh measurements keep one value while the
  robot's motion says it must have changed reads as ERROR too
  (:mod:`stairbot.control.stuck`).
  :meth:`Perception.why` says which.

Its timings, and the tolerances decisions that compare two sensors use, come
from the sensors' stated noise (:mod:`stairbot.control.tolerances`).  Pure
Python, on the controller's clock (the snapshots' times), deterministic.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterable
from enum import IntEnum

from stairbot.control.stuck import StuckWatch
from stairbot.control.timeline import value_at
from stairbot.control.tolerances import WINDOW, max_age, spec_max_age, window
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
from stairbot.readings import sensor_reading, snapshot

CONFIRM = 3
"""Measurements in a row that must agree before the kind seen changes."""
ODOMETER_HISTORY = 32
"""Ticks of odometer kept to place an old measurement (0.64 s at 20 ms)."""


class Kind(IntEnum):
    OK = 0
    NEAR = 1
    FAR = 2
    ERROR = 3


# bound once: an enum's member costs a slow attribute look-up, every sensor every tick
_KIND_OK, _KIND_NEAR, _KIND_FAR, _KIND_ERROR = Kind.OK, Kind.NEAR, Kind.FAR, Kind.ERROR
_STATUS_OK, _STATUS_OUT = SensorStatus.OK, SensorStatus.OUT_OF_RANGE


class _Track:
    """One sensor's recent measurements and the kind seen."""

    __slots__ = ("front", "max_age", "midpoint", "ok_keys", "median", "newest", "taken_s",
                 "kind", "run_kind", "run", "last_of_kind", "seen_ok")

    def __init__(self, front: bool, window: int, max_age: float, midpoint: float) -> None:
        self.front = front
        self.max_age = max_age
        self.midpoint = midpoint
        self.ok_keys: deque[float] = deque(maxlen=window)
        """The last OK measurements' distances, plus (front) the odometer when
        each was taken; emptied when the kind seen leaves OK."""
        self.median: float | None = None
        """The median of ok_keys (None: there are none), taken when they
        change: the ticks between two measurements read the same one."""
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
            age = spec_max_age(cfg, s.side_spec())
            lo, hi = s.side_range()
            for sid in SIDE_SENSORS:
                self._tracks[sid] = _Track(False, WINDOW, age, (lo + hi) / 2.0)
        self._odometer: deque[tuple[float, float]] = deque(maxlen=ODOMETER_HISTORY)
        self._why: dict[SensorId, str] = {}
        self._stuck = StuckWatch(cfg)

    def see(self, snap: Snapshot) -> Snapshot:
        """The snapshot as the algorithm should see it."""
        turns = snap.motors
        w0, w1, w2, w3 = self._wheels
        odometer = (turns[w0].turns + turns[w1].turns + turns[w2].turns + turns[w3].turns) \
            * self._metres_per_turn
        now = snap.time_s
        self._odometer.append((now, odometer))
        sensors: dict[SensorId, SensorReading] = {}
        tracks, why = self._tracks, self._why
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
                        median = track.median = _median(keys)
                        m = median - odometer if track.front else median
                        # immutable, and a new one costs: reuse an equal one (0.0 may be -0.0)
                        seen = track.seen_ok
                        if seen is None or seen.distance_m != m or m == 0.0:
                            seen = track.seen_ok = sensor_reading(m)
                        sensors[sid] = seen
                        continue
                self._measured(track, reading, now, odometer)
            elif now - age > track.taken_s + 1e-9:
                taken = now - age  # the odometer then places a front measurement
                self._measured(track, reading, taken,
                               value_at(self._odometer, taken) if track.front else 0.0)
            age = now - track.taken_s
            kept = track.median
            if track.kind is _KIND_OK and kept is not None and age <= track.max_age:
                # the common case, kept short: the median of recent OK measurements
                if why:  # most often empty: nothing to look up
                    why.pop(sid, None)
                sensors[sid] = sensor_reading(kept - odometer if track.front else kept,
                                              _STATUS_OK, age)
            else:
                sensors[sid] = self._verdict(sid, track, now, odometer)
        self._stuck.judge(snap, sensors, self._why)
        return snapshot(snap.time_s, sensors, snap.motors, snap.health, snap.imu)

    def distrust(self, sensor: SensorId, why: str) -> bool:
        """The algorithm found ``sensor`` reading wrong (``why``): if its
        measurements held one value, from the next tick on it reads as ERROR
        while that value holds, as a stuck one
        (:meth:`~stairbot.control.stuck.StuckWatch.distrust`)."""
        return self._stuck.distrust(sensor, why)

    def why(self, sensor: SensorId) -> str | None:
        """Why the sensor reads as ERROR now (stale, errors), or None."""
        return self._why.get(sensor)

    # -- per measurement ----------------------------------------------------------------
    def _measured(self, track: _Track, reading: SensorReading, taken: float,
                  odometer: float) -> None:
        """Take a new measurement, taken at ``taken`` (``odometer``: the drive's
        odometer then, which only a front track uses)."""
        status = reading.status
        if status is _STATUS_OK:
            if not math.isfinite(reading.distance_m):
                reading = SensorReading(reading.distance_m, SensorStatus.ERROR, reading.age_s)
                kind = _KIND_ERROR
            else:
                kind = _KIND_OK
                d = reading.distance_m
                track.ok_keys.append(d + odometer if track.front else d)
        elif status is _STATUS_OUT:
            kind = _KIND_NEAR if reading.distance_m < track.midpoint else _KIND_FAR
        else:
            kind = _KIND_ERROR
        if kind is not _KIND_OK and track.kind is not _KIND_OK:
            # OK measurements since the kind seen left OK that a bad one ends
            # came too few in a row to bring OK back: lone strays, not for
            # the median when it comes back
            track.ok_keys.clear()
        track.newest, track.taken_s = reading, taken
        track.last_of_kind[kind] = reading
        if kind is track.run_kind:
            track.run += 1
        else:
            track.run_kind, track.run = kind, 1
        if track.kind is None or (kind is not track.kind and track.run >= CONFIRM):
            if track.kind is _KIND_OK:
                # a fresh median when it comes back
                track.ok_keys.clear()
            track.kind = kind
        track.median = _median(track.ok_keys) if track.ok_keys else None

    # -- per tick -------------------------------------------------------------------------
    def _verdict(self, sid: SensorId, track: _Track, now: float, odometer: float
                 ) -> SensorReading:
        newest = track.newest
        assert newest is not None and track.kind is not None
        why = self._why
        age = now - track.taken_s
        if age > track.max_age:
            why[sid] = (f"stale: its newest measurement is {age:.2f} s old "
                        f"(at most {track.max_age:.2f} s)")
            return sensor_reading(newest.distance_m, SensorStatus.ERROR, age)
        kind = track.kind
        if kind is _KIND_OK:
            m = track.median
            if m is not None:
                if why:  # most often empty: nothing to look up
                    why.pop(sid, None)
                return sensor_reading(m - odometer if track.front else m, _STATUS_OK, age)
            why[sid] = "no valid measurement among its last ones"
            return sensor_reading(newest.distance_m, SensorStatus.ERROR, age)
        if kind is _KIND_ERROR:
            why[sid] = f"{CONFIRM} measurements in a row report an error"
            return sensor_reading(newest.distance_m, SensorStatus.ERROR, age)
        if why:
            why.pop(sid, None)
        held = track.last_of_kind[kind]
        return sensor_reading(held.distance_m, SensorStatus.OUT_OF_RANGE, age)


def _median(values: Iterable[float]) -> float:
    """statistics.median, without its generality (every sensor, every measurement)."""
    s = sorted(values)
    n = len(s)
    half = n // 2
    return s[half] if n % 2 else (s[half - 1] + s[half]) / 2
