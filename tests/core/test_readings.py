"""stairbot.readings makes each hardware record as its class would: equal,
hashed, printed, pickled and copied alike, every field set, and as frozen."""

from __future__ import annotations

import copy
import dataclasses
import math
import pickle
from typing import Any

import pytest

from stairbot import readings
from stairbot.hardware import (
    Imu,
    MotorId,
    MotorState,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
)

IMU = Imu(1.5, -0.25, 3.0, -4.0, 0.02)
SENSORS = {SensorId.SFR: SensorReading(0.5), SensorId.SBL: SensorReading(0.1, age_s=0.03)}
MOTORS = {MotorId.MWF: MotorState(2.0, 0.5), MotorId.MTB: MotorState(-1.0, 0.0, "stall")}

CASES: list[tuple[Any, Any]] = [
    (readings.sensor_reading(0.25), SensorReading(0.25)),
    (readings.sensor_reading(2.0, SensorStatus.OUT_OF_RANGE, 0.06),
     SensorReading(2.0, SensorStatus.OUT_OF_RANGE, 0.06)),
    (readings.sensor_reading(math.inf, SensorStatus.ERROR, math.inf),
     SensorReading(math.inf, SensorStatus.ERROR, math.inf)),
    (readings.motor_state(3.5), MotorState(3.5)),
    (readings.motor_state(-1.0, 0.75, "overcurrent"), MotorState(-1.0, 0.75, "overcurrent")),
    (readings.imu(1.5, -0.25, 3.0, -4.0, 0.02), IMU),
    (readings.imu(2.0, 0.0), Imu(2.0, 0.0)),
    (readings.snapshot(12.5, SENSORS, MOTORS, {"battery_v": 24.1}, IMU),
     Snapshot(12.5, SENSORS, MOTORS, {"battery_v": 24.1}, IMU)),
    (readings.snapshot(0.0, {}, {}, {}, None), Snapshot(0.0, {}, {})),
]


@pytest.mark.parametrize(("made", "expected"), CASES, ids=lambda v: type(v).__name__)
def test_a_record_made_here_is_the_one_its_class_makes(made: Any, expected: Any) -> None:
    assert type(made) is type(expected)
    for f in dataclasses.fields(expected):  # a field added to the class but not here fails
        assert getattr(made, f.name) == getattr(expected, f.name), f.name
    assert made == expected and expected == made
    if not isinstance(made, Snapshot):  # a snapshot holds dicts: no hash either way
        assert hash(made) == hash(expected)
    assert repr(made) == repr(expected)
    assert dataclasses.asdict(made) == dataclasses.asdict(expected)
    assert pickle.loads(pickle.dumps(made)) == expected
    assert copy.deepcopy(made) == expected
    assert dataclasses.replace(made) == expected


@pytest.mark.parametrize(("made", "expected"), CASES, ids=lambda v: type(v).__name__)
def test_a_record_made_here_is_frozen(made: Any, expected: Any) -> None:
    name = dataclasses.fields(expected)[0].name
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(made, name, 1.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        delattr(made, name)
