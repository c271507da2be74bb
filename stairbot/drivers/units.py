"""Conversions between the wire's integers and stairbot's units and types.

Speeds: turns/s <-> milli-turns/s (int16); turn counters: turns <-> milli-turns
(int32); distances: metres <-> millimetres (uint16).  Rounding is to the
nearest; values beyond a wire type's range are clamped, never wrapped.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from stairbot.drivers.messages import (
    INT16_MAX,
    INT32_MAX,
    MOTOR_CHANNELS,
    MotorFault,
    MotorTelemetry,
    SensorCode,
    SensorTelemetry,
    SetLiftSpeeds,
    SetWheelSpeeds,
)
from stairbot.hardware import MotorId, MotorState, SensorReading, SensorStatus


def _clamp(value: int, low: int, high: int) -> int:
    return low if value < low else high if value > high else value


def speed_to_wire(tps: float) -> int:
    """turns/s -> milli-turns/s (nearest, clamped to int16).  A speed that is
    not a finite number is sent as 0 (stop; a lift holds), as ``sim://`` does,
    rather than raising out of the control loop or running a motor flat out."""
    if not math.isfinite(tps):
        return 0
    return _clamp(round(tps * 1000.0), -INT16_MAX, INT16_MAX)


def speed_from_wire(mtps: int) -> float:
    return mtps / 1000.0


def turns_to_wire(turns: float) -> int:
    """turns -> milli-turns (nearest, clamped to int32)."""
    return _clamp(round(turns * 1000.0), -INT32_MAX, INT32_MAX)


def turns_from_wire(mt: int) -> float:
    return mt / 1000.0


def distance_to_wire(metres: float) -> int:
    """metres -> millimetres (nearest, clamped to uint16)."""
    return _clamp(round(metres * 1000.0), 0, 65535)


def distance_from_wire(mm: int) -> float:
    return mm / 1000.0


_SENSOR_STATUS = {
    SensorCode.OK: SensorStatus.OK,
    SensorCode.OUT_OF_RANGE: SensorStatus.OUT_OF_RANGE,
    SensorCode.ERROR: SensorStatus.ERROR,
}
_SENSOR_CODE = {v: k for k, v in _SENSOR_STATUS.items()}


def sensor_code(status: SensorStatus) -> int:
    return int(_SENSOR_CODE[status])


def reading_from_wire(t: SensorTelemetry) -> SensorReading:
    """The SensorReading a SensorTelemetry stands for (an unknown status
    code reads as ERROR)."""
    try:
        status = _SENSOR_STATUS[SensorCode(t.status)]
    except ValueError:
        status = SensorStatus.ERROR
    return SensorReading(distance_from_wire(t.distance_mm), status)


def fault_name(code: int) -> str | None:
    """'estop', 'watchdog', ... for a MotorFault code; None for NONE."""
    if code == MotorFault.NONE:
        return None
    try:
        return MotorFault(code).name.lower()
    except ValueError:
        return f"fault_{code}"


def state_from_wire(t: MotorTelemetry) -> MotorState:
    return MotorState(turns_from_wire(t.turns_mt), speed_from_wire(t.speed_mtps),
                      fault_name(t.fault))


def speeds_to_wire(speeds: Mapping[MotorId, float]) -> tuple[SetWheelSpeeds, SetLiftSpeeds]:
    """The two frames that set every motor's speed; motors left out get 0."""
    w = [speed_to_wire(speeds.get(m, 0.0)) for m in MOTOR_CHANNELS]
    return SetWheelSpeeds(w[0], w[1], w[2], w[3]), SetLiftSpeeds(w[4], w[5])
