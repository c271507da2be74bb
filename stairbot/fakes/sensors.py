"""The ideal distance sensor model: range limits, resolution, seeded noise, faults.

(The realistic models -- cone, timing, outliers, dropouts -- are in
:mod:`stairbot.fakes.sensor_model`; its ``ideal`` preset reads exactly as this.)

A true distance (or None: nothing to see) becomes a
:class:`~stairbot.hardware.SensorReading` the way a small time-of-flight or
infrared ranger reports it:

* scenario faults first: an ``offset`` fault adds its offset while active; an
  ``error`` fault makes the sensor report ERROR (distance 0.0) while active;
  a fault is active for ``at <= t < at + duration`` of simulated time (no
  duration: until the end);
* Gaussian noise of the scenario's standard deviation, drawn from a
  ``random.Random`` of the sensor's own, seeded from the scenario's seed and
  the sensor's name: one draw per reading, whatever the reading turns out to
  be, so the same run gives the same readings bit for bit;
* beyond the maximum range (or nothing there): OUT_OF_RANGE at the maximum;
  nearer than the minimum: OUT_OF_RANGE at the minimum;
* otherwise OK, rounded to the sensor's resolution.
"""

from __future__ import annotations

import random
from collections.abc import Iterable

from stairbot.hardware import SensorId, SensorReading, SensorStatus
from stairbot.scenario import Fault


def sensor_rng(seed: int, sensor: SensorId) -> random.Random:
    """The noise generator of one sensor: independent per sensor, fixed per seed."""
    return random.Random(f"stairbot-sensor:{seed}:{sensor.value}")


def active_faults(faults: Iterable[Fault], t: float) -> tuple[float, bool]:
    """The summed offset of the offset faults active at ``t``, and whether an
    error fault is active."""
    offset, error = 0.0, False
    for f in faults:
        if t >= f.at and (f.duration is None or t < f.at + f.duration):
            if f.kind == "error":
                error = True
            else:
                offset += f.offset
    return offset, error


class RangeSensor:
    """One distance sensor's model (see the module docstring)."""

    def __init__(self, sensor: SensorId, min_range: float, max_range: float,
                 resolution: float, noise: float, seed: int,
                 faults: Iterable[Fault] = ()) -> None:
        self.sensor = sensor
        self.min_range = min_range
        self.max_range = max_range
        self.resolution = resolution
        self.noise = noise
        self._gauss = sensor_rng(seed, sensor).gauss
        self.faults = tuple(f for f in faults if f.sensor == sensor.value)
        self._far = SensorReading(max_range, SensorStatus.OUT_OF_RANGE)
        self._near = SensorReading(min_range, SensorStatus.OUT_OF_RANGE)
        self._error = SensorReading(0.0, SensorStatus.ERROR)
        self._by_step: dict[int, SensorReading] = {}

    def measure(self, true_distance: float | None, t: float) -> SensorReading:
        """The reading at simulated time ``t`` of a target ``true_distance`` metres
        away (None: nothing in the beam)."""
        noise = self._gauss(0.0, self.noise) if self.noise > 0.0 else 0.0
        if self.faults:
            offset, error = active_faults(self.faults, t)
            if error:
                return self._error
        else:
            offset = 0.0
        if true_distance is None:
            return self._far
        d = true_distance + offset + noise
        if d > self.max_range:
            return self._far
        if d < self.min_range:
            return self._near
        if self.resolution <= 0.0:
            return SensorReading(d, SensorStatus.OK)
        # readings are whole multiples of the resolution: share one object per value
        k = round(d / self.resolution)
        reading = self._by_step.get(k)
        if reading is None:
            value = min(max(round(k * self.resolution, 9), self.min_range), self.max_range)
            reading = self._by_step[k] = SensorReading(value, SensorStatus.OK)
        return reading
