"""The distance sensor as it was before the sensor models (issue 10), kept
frozen as the oracle the ``ideal`` preset must read as, bit for bit
(tests/fakes/test_sensor_presets.py).  Not used by stairbot itself."""

from __future__ import annotations

from collections.abc import Iterable

from stairbot.fakes.sensors import active_faults, sensor_rng
from stairbot.hardware import SensorId, SensorReading, SensorStatus
from stairbot.inputs.scenario import Fault


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
