"""Perception: what the algorithm sees of the distance sensors.

Every snapshot passes through :class:`Perception` before any phase sees it.
Per sensor it keeps the last ``WINDOW`` readings and reports their median —
which no single outlier moves — with the status most of them agree on: a
reading the sensor gave once (a spike, a dropout, a lone "out of range")
decides nothing.  The front sensors look along the drive: each of their
older readings is carried forward by the distance the wheels have driven
since, so the median of a moving robot is today's distance, not the one of
two ticks ago.  Decisions that compare two sensors ("equal", the standing
rule) use tolerances derived from the sensors' stated noise
(``[sensors] noise`` in the robot config), not from a guess.

Pure Python, on the controller's clock (the snapshots' times), deterministic.
"""

from __future__ import annotations

import math
from collections import deque

from stairbot.config import RobotConfig
from stairbot.hardware import (
    FRONT_SENSORS,
    WHEEL_MOTORS,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
)

WINDOW = 5
"""Readings per sensor the median is taken over (100 ms at the 20 ms tick)."""
SIGMAS = 4.0
"""A difference counts as real when it exceeds this many of its own sigmas."""
MEDIAN_EFFICIENCY = 1.25
"""The median of n normal samples has about 1.25 times the sigma of their mean."""


def median_sigma(noise: float, n: int = WINDOW) -> float:
    """Sigma of the median of ``n`` readings of a sensor with sigma ``noise``."""
    return MEDIAN_EFFICIENCY * noise / math.sqrt(n)


def still_tolerance(cfg: RobotConfig, samples: int) -> float:
    """Like :func:`pair_tolerance`, for the mean of ``samples`` filtered
    differences taken standing still."""
    sigma_diff = math.sqrt(2.0) * MEDIAN_EFFICIENCY * cfg.sensors.noise / math.sqrt(samples)
    return max(cfg.algorithm.equal_tolerance, SIGMAS * sigma_diff)


def pair_tolerance(cfg: RobotConfig, smoothing: float = 1.0) -> float:
    """How far two filtered readings of one surface may differ and still be
    "equal": equal_tolerance, or SIGMAS sigmas of their difference if the
    sensors are noisier than that allows.  ``smoothing`` is the weight of an
    exponential smoothing applied on top (1.0: none)."""
    sigma_diff = math.sqrt(2.0) * median_sigma(cfg.sensors.noise)
    sigma_diff *= math.sqrt(smoothing / (2.0 - smoothing))
    return max(cfg.algorithm.equal_tolerance, SIGMAS * sigma_diff)


Sample = tuple[SensorReading, float]
"""A reading and the odometer (mean wheel counter, metres) when it was taken."""


class Perception:
    """Filters snapshots (see the module docstring).  One per controller."""

    def __init__(self, cfg: RobotConfig, window: int = WINDOW) -> None:
        self.window = window
        self._metres_per_turn = cfg.wheel_circumference
        self._buffers: dict[SensorId, deque[Sample]] = {
            s: deque(maxlen=window) for s in SensorId}

    def see(self, snap: Snapshot) -> Snapshot:
        """The snapshot as the algorithm should see it."""
        odometer = sum(snap.turns(m) for m in WHEEL_MOTORS) / len(WHEEL_MOTORS) \
            * self._metres_per_turn
        sensors: dict[SensorId, SensorReading] = {}
        for sid, reading in snap.sensors.items():
            buf = self._buffers[sid]
            buf.append((reading, odometer))
            sensors[sid] = _agree(buf, odometer if sid in FRONT_SENSORS else None)
        return Snapshot(snap.time_s, sensors, snap.motors, snap.health, snap.imu)


def _agree(buf: deque[Sample], odometer: float | None) -> SensorReading:
    """The window's verdict: the status most readings share (ties go to the
    newest reading's), and the median distance of the readings with it —
    each carried forward to ``odometer`` (a forward-looking sensor)."""
    newest = buf[-1][0]
    if len(buf) == 1:
        return newest
    status = newest.status
    if not all(r.status is status for r, _ in buf):  # the common case needs no count
        counts: dict[SensorStatus, int] = {}
        for r, _ in buf:
            counts[r.status] = counts.get(r.status, 0) + 1
        top = max(counts.values())
        if counts[status] != top:
            status = next(s for s, c in counts.items() if c == top)
    if status is SensorStatus.OK and odometer is not None:
        values = [r.distance_m - (odometer - at) for r, at in buf if r.status is status]
    else:
        values = [r.distance_m for r, _ in buf if r.status is status]
    if status is SensorStatus.ERROR or not all(math.isfinite(v) for v in values):
        return SensorReading(newest.distance_m if newest.status is status else values[-1], status)
    return SensorReading(_median(values), status)


def _median(values: list[float]) -> float:
    """statistics.median, without its generality (a hot path: every sensor, every tick)."""
    s = sorted(values)
    n = len(s)
    half = n // 2
    return s[half] if n % 2 else (s[half - 1] + s[half]) / 2
