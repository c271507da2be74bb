"""Conversions between the wire's integers and stairbot's units and types.

Speeds: turns/s <-> milli-turns/s (int16); turn counters: turns <-> milli-turns
(int32); distances: metres <-> millimetres (uint16); ages: seconds <->
milliseconds (uint16, saturating at AGE_MAX_MS: "this old or older"); IMU
angles: degrees <-> 0.01 degree (int16, within +-180 degrees) and rates:
degrees/s <-> 0.1 degree/s (int16).  Rounding is to the nearest; values beyond
a wire type's range are clamped, never wrapped.

Going to the wire (the boards' side) never raises: a value that is not a
number goes as a status that says so (a sensor's ERROR, an IMU's ERROR).
Coming from the wire, a value the protocol does not allow is never turned
into a number: :func:`imu_from_wire` raises TelemetryValueError for it.
"""

from __future__ import annotations

import math

from stairbot.drivers.messages import (
    AGE_MAX_MS,
    ANGLE_MAX_CDEG,
    INT16_MAX,
    INT16_NONE,
    INT32_MAX,
    MOTOR_CHANNELS,
    ImuAxis,
    ImuCode,
    ImuTelemetry,
    MotorFault,
    MotorTelemetry,
    SensorCode,
    SensorTelemetry,
    SetLiftSpeeds,
    SetWheelSpeeds,
    TelemetryValueError,
)
from stairbot.hardware import Imu, MotorState, SensorReading, SensorStatus, Speeds


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


def age_to_wire(seconds: float) -> int:
    """seconds -> ms (nearest), saturating at AGE_MAX_MS ("this old or
    older"); a negative age is 0, and an age that is not a number saturates
    (nothing says the reading is any younger)."""
    if seconds != seconds or seconds >= AGE_MAX_MS / 1000.0:
        return AGE_MAX_MS
    if seconds <= 0.0:
        return 0
    return min(round(seconds * 1000.0), AGE_MAX_MS)


def age_from_wire(ms: int) -> float:
    return ms / 1000.0


_SENSOR_STATUS = {
    SensorCode.OK: SensorStatus.OK,
    SensorCode.OUT_OF_RANGE: SensorStatus.OUT_OF_RANGE,
    SensorCode.ERROR: SensorStatus.ERROR,
}
_SENSOR_CODE = {v: k for k, v in _SENSOR_STATUS.items()}


def sensor_code(status: SensorStatus) -> int:
    return int(_SENSOR_CODE[status])


def reading_to_wire(channel: int, reading: SensorReading, sample: int,
                    since_s: float = 0.0) -> SensorTelemetry:
    """A board's SensorTelemetry for ``reading``, ``since_s`` seconds after the
    reading's own time (its age grows by that).  A distance that is not a
    number goes as ERROR (the distance then means nothing: 0)."""
    if not math.isfinite(reading.distance_m):
        return SensorTelemetry(channel, int(SensorCode.ERROR), 0, sample,
                               age_to_wire(reading.age_s + since_s))
    return SensorTelemetry(channel, sensor_code(reading.status),
                           distance_to_wire(reading.distance_m), sample,
                           age_to_wire(reading.age_s + since_s))


def reading_from_wire(t: SensorTelemetry, transit_s: float = 0.0) -> SensorReading:
    """The SensorReading a SensorTelemetry stands for (an unknown status
    code reads as ERROR).  Its age is the board's, plus ``transit_s``: how long
    before the snapshot's time the board may have sent it."""
    try:
        status = _SENSOR_STATUS[SensorCode(t.status)]
    except ValueError:
        status = SensorStatus.ERROR
    return SensorReading(distance_from_wire(t.distance_mm), status,
                         age_from_wire(t.age_ms) + transit_s)


def imu_to_wire(imu: Imu | None, axis: ImuAxis, since_s: float = 0.0) -> ImuTelemetry:
    """A board's ImuTelemetry for one axis of ``imu`` (None: no IMU fitted,
    ABSENT), ``since_s`` seconds after the IMU's own time.  An angle or rate
    that is not a number, or an angle beyond +-180 degrees, goes as ERROR; a
    rate beyond the int16 range saturates ("this fast or faster")."""
    if imu is None:
        return ImuTelemetry(int(axis), int(ImuCode.ABSENT), 0, 0, 0)
    angle, rate = ((imu.pitch_deg, imu.pitch_rate_dps) if axis == ImuAxis.PITCH
                   else (imu.roll_deg, imu.roll_rate_dps))
    age = age_to_wire(imu.age_s + since_s)
    if not (math.isfinite(angle) and math.isfinite(rate)):
        return ImuTelemetry(int(axis), int(ImuCode.ERROR), 0, 0, age)
    cdeg = round(angle * 100.0)
    if abs(cdeg) > ANGLE_MAX_CDEG:
        return ImuTelemetry(int(axis), int(ImuCode.ERROR), 0, 0, age)
    return ImuTelemetry(int(axis), int(ImuCode.OK), cdeg,
                        _clamp(round(rate * 10.0), -INT16_MAX, INT16_MAX), age)


def _imu_axis(t: ImuTelemetry) -> tuple[float, float]:
    """(degrees, degrees/s) of one OK axis; TelemetryValueError for a value
    the protocol does not allow."""
    name = "pitch" if t.axis == ImuAxis.PITCH else "roll" if t.axis == ImuAxis.ROLL else "?"
    if t.angle_cdeg == INT16_NONE or abs(t.angle_cdeg) > ANGLE_MAX_CDEG:
        raise TelemetryValueError(
            f"ImuTelemetry ({name}) angle_cdeg = {t.angle_cdeg}: allowed "
            f"-{ANGLE_MAX_CDEG}..{ANGLE_MAX_CDEG} (+-180.00 degrees)")
    if t.rate_ddps == INT16_NONE:
        raise TelemetryValueError(
            f"ImuTelemetry ({name}) rate_ddps = {t.rate_ddps}: allowed "
            f"-{INT16_MAX}..{INT16_MAX} (-32768 is no number)")
    return t.angle_cdeg / 100.0, t.rate_ddps / 10.0


def imu_from_wire(pitch: ImuTelemetry, roll: ImuTelemetry, transit_s: float = 0.0
                  ) -> Imu | None:
    """The Imu the two axes of one reply stand for, or None unless both say
    OK (ABSENT, ERROR or an unknown status: no IMU).  Its age is the older
    axis's plus ``transit_s`` (see reading_from_wire).  Raises
    TelemetryValueError when an OK axis holds a value the protocol does not
    allow: such a frame is a broken board, not an attitude."""
    if pitch.status != ImuCode.OK or roll.status != ImuCode.OK:
        return None
    pitch_deg, pitch_rate = _imu_axis(pitch)
    roll_deg, roll_rate = _imu_axis(roll)
    return Imu(pitch_deg, roll_deg, pitch_rate, roll_rate,
               age_from_wire(max(pitch.age_ms, roll.age_ms)) + transit_s)


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


def speeds_to_wire(speeds: Speeds) -> tuple[SetWheelSpeeds, SetLiftSpeeds]:
    """The two frames that set every motor's speed; motors left out get 0."""
    w = [speed_to_wire(speeds.get(m, 0.0)) for m in MOTOR_CHANNELS]
    return SetWheelSpeeds(w[0], w[1], w[2], w[3]), SetLiftSpeeds(w[4], w[5])
