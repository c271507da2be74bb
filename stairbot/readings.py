"""Make the hardware's frozen value records (:class:`SensorReading`,
:class:`MotorState`, :class:`Imu`, :class:`Snapshot`) at the cost of their
fields, for the code that makes them every tick: the simulated robot and
perception.

A frozen dataclass's ``__init__`` is Python that sets each field through
``object.__setattr__``: about a microsecond a record, some twenty records a
tick.  These functions make the same record from its class's ``__new__`` and
each slot's own setter, which mypyc calls directly (this module is compiled:
stairbot/compiled.py).  What they make is the record its class would make
from the same values, equal, hashed, printed and pickled alike, and as
frozen; tests/core/test_readings.py holds each to its class, field by field.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, Final

from stairbot.hardware import (
    Imu,
    MotorId,
    MotorState,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
)

# Final: mypyc keeps these in the module's C statics, not its dict
_new: Final[Any] = object.__new__
_STATUS_OK: Final = SensorStatus.OK


def _setter(cls: type, name: str) -> Callable[[object, object], None]:
    """The setter of ``cls``'s slot ``name`` (a frozen record's own __setattr__ refuses)."""
    setter: Callable[[object, object], None] = cls.__dict__[name].__set__
    return setter


_R_DISTANCE: Final = _setter(SensorReading, "distance_m")
_R_STATUS: Final = _setter(SensorReading, "status")
_R_AGE: Final = _setter(SensorReading, "age_s")
_M_TURNS: Final = _setter(MotorState, "turns")
_M_SPEED: Final = _setter(MotorState, "speed_tps")
_M_FAULT: Final = _setter(MotorState, "fault")
_I_PITCH: Final = _setter(Imu, "pitch_deg")
_I_ROLL: Final = _setter(Imu, "roll_deg")
_I_PITCH_RATE: Final = _setter(Imu, "pitch_rate_dps")
_I_ROLL_RATE: Final = _setter(Imu, "roll_rate_dps")
_I_AGE: Final = _setter(Imu, "age_s")
_S_TIME: Final = _setter(Snapshot, "time_s")
_S_SENSORS: Final = _setter(Snapshot, "sensors")
_S_MOTORS: Final = _setter(Snapshot, "motors")
_S_HEALTH: Final = _setter(Snapshot, "health")
_S_IMU: Final = _setter(Snapshot, "imu")


def sensor_reading(distance_m: float, status: SensorStatus = _STATUS_OK,
                   age_s: float = 0.0) -> SensorReading:
    """``SensorReading(distance_m, status, age_s)``."""
    reading: SensorReading = _new(SensorReading)
    _R_DISTANCE(reading, distance_m)
    _R_STATUS(reading, status)
    _R_AGE(reading, age_s)
    return reading


def motor_state(turns: float, speed_tps: float = 0.0, fault: str | None = None) -> MotorState:
    """``MotorState(turns, speed_tps, fault)``."""
    state: MotorState = _new(MotorState)
    _M_TURNS(state, turns)
    _M_SPEED(state, speed_tps)
    _M_FAULT(state, fault)
    return state


def imu(pitch_deg: float, roll_deg: float, pitch_rate_dps: float = 0.0,
        roll_rate_dps: float = 0.0, age_s: float = 0.0) -> Imu:
    """``Imu(pitch_deg, roll_deg, pitch_rate_dps, roll_rate_dps, age_s)``."""
    out: Imu = _new(Imu)
    _I_PITCH(out, pitch_deg)
    _I_ROLL(out, roll_deg)
    _I_PITCH_RATE(out, pitch_rate_dps)
    _I_ROLL_RATE(out, roll_rate_dps)
    _I_AGE(out, age_s)
    return out


def snapshot(time_s: float, sensors: Mapping[SensorId, SensorReading],
             motors: Mapping[MotorId, MotorState], health: Mapping[str, float],
             imu: Imu | None) -> Snapshot:
    """``Snapshot(time_s, sensors, motors, health, imu)`` (every field given:
    ``health`` has no shared default to fall back on)."""
    snap: Snapshot = _new(Snapshot)
    _S_TIME(snap, time_s)
    _S_SENSORS(snap, sensors)
    _S_MOTORS(snap, motors)
    _S_HEALTH(snap, health)
    _S_IMU(snap, imu)
    return snap
