"""Every signal the console can plot (key ``v``), each with its unit, read
out of the robot's readings (:class:`~stairbot.hardware.Snapshot`): the
IMU's pitch and roll and their rates, each distance sensor and how old its
measurement is, each motor's speed and turn count, the lifts in mm, and the
link's figures (frames per second, round trips, errors and the other
counters a driver puts in ``Snapshot.health``).

Pure: no Textual here.  :class:`Samples` keeps the readings over the last
:data:`~stairbot.console.history.WINDOW_S` seconds of robot time, one a
reading, newer than the last (an idle robot read again while its clock
stands adds nothing: a signal is never extended with samples it did not
give)."""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from stairbot.console.freshness import STALE_S
from stairbot.console.history import WINDOW_S
from stairbot.hardware import (
    BASE_SENSORS,
    LIFT_MOTORS,
    SIDE_SENSORS,
    MotorId,
    SensorStatus,
    Snapshot,
)

MAX_PICKED = 4
"""Signals on one plot at most (more would be a tangle of lines)."""
MAX_UNITS = 2
"""Units on one plot at most: one y axis each, left and right."""

ERROR_KEYS = ("crc_errors", "malformed", "stray", "error_frames")
"""The link's error counters, summed as ``errors`` (as the link panel sums them)."""
LINK_NAMES = {
    "frames_per_s": ("frames per second", "frames/s"),
    "rtt_ms": ("round trip, latest", "ms"),
    "rtt_median_ms": ("round trip, median", "ms"),
    "rtt_p99_ms": ("round trip, p99", "ms"),
}
"""Link figures with a name and unit of their own; every other key of
``Snapshot.health`` is a counter (``count``)."""

Reading = tuple[float, Snapshot]
"""A reading on the plot's time axis: (time s, the snapshot)."""


@dataclass(frozen=True)
class Signal:
    """One plottable value: ``key`` names it (``SFR``, ``MWF.speed``,
    ``link.lost``), ``label`` as the operator reads it, ``unit`` its unit,
    ``group`` where the picker lists it."""

    key: str
    label: str
    unit: str
    group: str
    value: Callable[[Snapshot], float | None]
    """Its value in a reading: None where the reading does not carry it, nan
    where it carries no number (a sensor in ERROR)."""
    age: Callable[[Snapshot], float] | None = None
    """How long before the reading the value was measured (a sensor's, the
    IMU's own count), when the reading says."""
    short: str = ""
    """The label in the plot's legend, where room is short ("": the label)."""

    @property
    def brief(self) -> str:
        """The legend's label."""
        return self.short or self.label

    @property
    def name(self) -> str:
        """``SFR distance (m)``: the label with its unit."""
        return f"{self.label} ({self.unit})"


def _sensor(sensor: str) -> Signal:
    def value(s: Snapshot) -> float | None:
        r = s.sensors.get(sensor)  # type: ignore[call-overload]
        if r is None:
            return None
        return math.nan if r.status is SensorStatus.ERROR else r.distance_m

    def age(s: Snapshot) -> float:
        r = s.sensors.get(sensor)  # type: ignore[call-overload]
        return 0.0 if r is None else r.age_s

    return Signal(sensor, f"{sensor} distance", "m", "distance sensors", value, age,
                  short=sensor)


def _sensor_age(sensor: str) -> Signal:
    def value(s: Snapshot) -> float | None:
        r = s.sensors.get(sensor)  # type: ignore[call-overload]
        return None if r is None else r.age_s * 1000

    return Signal(f"{sensor}.age", f"{sensor} measurement age", "ms", "distance sensors",
                  value)


def _motor(motor: MotorId, what: str) -> Signal:
    def value(s: Snapshot) -> float | None:
        m = s.motors.get(motor)
        return None if m is None else (m.speed_tps if what == "speed" else m.turns)

    label, unit = ("speed", "turn/s") if what == "speed" else ("count", "turns")
    return Signal(f"{motor.value}.{what}", f"{motor.value} {label}", unit, "motors", value)


def _lift(motor: MotorId, m_per_turn: float) -> Signal:
    def value(s: Snapshot) -> float | None:
        m = s.motors.get(motor)
        return None if m is None else m.turns * m_per_turn * 1000

    return Signal(f"{motor.value}.lift", f"{motor.value} lift", "mm", "lifts", value)


def _imu(field: str, label: str, unit: str) -> Signal:
    def value(s: Snapshot) -> float | None:
        return None if s.imu is None else float(getattr(s.imu, field))

    def age(s: Snapshot) -> float:
        return 0.0 if s.imu is None else s.imu.age_s

    return Signal(field, label, unit, "IMU", value, age)


def _link(key: str) -> Signal:
    label, unit = LINK_NAMES.get(key, (key.replace("_", " "), "count"))

    def value(s: Snapshot) -> float | None:
        return s.health.get(key)

    return Signal(f"link.{key}", f"link {label}", unit, "link", value)


def _link_errors(s: Snapshot) -> float | None:
    if not any(k in s.health for k in ERROR_KEYS):
        return None
    return sum(s.health.get(k, 0.0) for k in ERROR_KEYS)


def catalogue(readings: Iterable[Snapshot], m_per_turn: float, *,
              side_pair: bool = False) -> tuple[Signal, ...]:
    """Every signal the console knows: those every robot has (the IMU, the
    four sensors, each motor, the lifts), the side pair's when the robot has
    it (``side_pair``) or a reading carries it, and the link figures the
    ``readings`` carry (a simulation's carry none).  ``m_per_turn``: the
    lifts' travel a turn (the config's)."""
    carried_sides = side_pair
    health: list[str] = []
    for snap in readings:
        carried_sides = carried_sides or any(s in snap.sensors for s in SIDE_SENSORS)
        health.extend(k for k in snap.health if k not in health)
    sensors = BASE_SENSORS + (SIDE_SENSORS if carried_sides else ())
    out: list[Signal] = [
        _imu("pitch_deg", "pitch", "°"), _imu("roll_deg", "roll", "°"),
        _imu("pitch_rate_dps", "pitch rate", "°/s"), _imu("roll_rate_dps", "roll rate", "°/s"),
    ]
    out += [_sensor(s.value) for s in sensors]
    out += [_lift(m, m_per_turn) for m in LIFT_MOTORS]
    out += [_motor(m, what) for m in MotorId for what in ("speed", "turns")]
    out += [_sensor_age(s.value) for s in sensors]
    if health:
        if any(k in health for k in ERROR_KEYS):
            out.append(Signal("link.errors", "link errors", "count", "link", _link_errors))
        out += [_link(k) for k in sorted(health, key=_link_order)]
    return tuple(out)


def _link_order(key: str) -> tuple[int, str]:
    """The named figures first, in :data:`LINK_NAMES`' order, then the counters."""
    names = list(LINK_NAMES)
    return (names.index(key), "") if key in names else (len(names), key)


def by_key(signals: Iterable[Signal]) -> dict[str, Signal]:
    return {s.key: s for s in signals}


def fits(picked: Sequence[Signal]) -> str:
    """Why ``picked`` cannot go on one plot ("": it can): at most
    :data:`MAX_PICKED` signals in at most :data:`MAX_UNITS` units."""
    if len(picked) > MAX_PICKED:
        return f"at most {MAX_PICKED} signals on one plot"
    units = units_of(picked)
    if len(units) > MAX_UNITS:
        return (f"at most {MAX_UNITS} units on one plot (one y axis each): "
                f"{', '.join(units)} picked")
    return ""


def units_of(picked: Iterable[Signal]) -> list[str]:
    """The units of ``picked``, each once, in order: the first is the left
    axis's, the second the right's."""
    out: list[str] = []
    for s in picked:
        if s.unit not in out:
            out.append(s.unit)
    return out


@dataclass(frozen=True)
class Series:
    """A signal's points over the window: ``xs`` (time s) and ``ys`` (its
    unit), only where a reading carried a number; ``last`` its value in the
    latest reading (None: that reading does not carry it; nan: ERROR);
    ``stale``: the latest value says nothing about now (the reading is old,
    or the sensor has not measured for :data:`~stairbot.console.freshness.STALE_S`)."""

    signal: Signal
    xs: tuple[float, ...]
    ys: tuple[float, ...]
    last: float | None
    stale: bool


def series(signal: Signal, readings: Sequence[Reading], read_age_s: float | None) -> Series:
    """``signal`` over ``readings``; ``read_age_s``: wall (or, replaying,
    recording) seconds since the latest reading was taken (None: never)."""
    xs: list[float] = []
    ys: list[float] = []
    for t, snap in readings:
        y = signal.value(snap)
        if y is not None and math.isfinite(y):
            xs.append(t)
            ys.append(y)
    last = signal.value(readings[-1][1]) if readings else None
    stale = read_age_s is None or read_age_s > STALE_S or last is None
    if not stale and signal.age is not None and signal.age(readings[-1][1]) > STALE_S:
        stale = True
    return Series(signal, tuple(xs), tuple(ys), last, stale)


def thin(xs: Sequence[float], ys: Sequence[float], buckets: int
         ) -> tuple[list[float], list[float]]:
    """At most two points a bucket of equal time, the lowest and the highest
    in time order, and the first and last points kept: what a plot
    ``buckets`` columns wide can show of ``xs``, ``ys`` (a spike stays, and
    drawing costs what the width does, not the number of readings)."""
    if len(xs) <= 2 * buckets + 2 or buckets < 1:
        return list(xs), list(ys)
    first, span = xs[0], (xs[-1] - xs[0]) or 1.0
    out_x, out_y = [xs[0]], [ys[0]]
    lo = hi = -1
    bucket = 0
    for i in range(1, len(xs) - 1):
        b = min(buckets - 1, int((xs[i] - first) / span * buckets))
        if b != bucket and lo >= 0:
            for j in sorted({lo, hi}):
                out_x.append(xs[j])
                out_y.append(ys[j])
            lo = hi = -1
        bucket = b
        if lo < 0 or ys[i] < ys[lo]:
            lo = i
        if hi < 0 or ys[i] > ys[hi]:
            hi = i
    for j in sorted({lo, hi} - {-1}):
        out_x.append(xs[j])
        out_y.append(ys[j])
    out_x.append(xs[-1])
    out_y.append(ys[-1])
    return out_x, out_y


class Samples:
    """The readings over the last ``window_s`` seconds of robot time, one a
    reading newer than the last kept; a clock that went back (another
    robot, a reset) starts afresh."""

    def __init__(self, window_s: float = WINDOW_S) -> None:
        self.window_s = window_s
        self._kept: deque[Reading] = deque()

    def add(self, snap: Snapshot | None) -> None:
        if snap is None:
            return
        kept, t = self._kept, snap.time_s
        if kept:
            last = kept[-1][0]
            if t == last:
                return
            if t < last:
                kept.clear()
        kept.append((t, snap))
        while kept[0][0] < t - self.window_s:
            kept.popleft()

    def clear(self) -> None:
        self._kept.clear()

    def readings(self) -> tuple[Reading, ...]:
        return tuple(self._kept)
