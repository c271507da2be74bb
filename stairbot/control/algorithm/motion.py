"""Readings and motions shared by the phases.

What the sensors say (measurable, nothing ahead, the pair's mean) and how a
motion approaches its target: full speed until it must brake, then braking
at a constant rate to a stop on the target, never below a floor, so it stops
within a fraction of a millimetre (wheels) or a few hundredths of a turn
(lifts) of it.
"""

from __future__ import annotations

import math
from typing import Final

from stairbot.hardware import (
    BACK_SENSORS,
    FRONT_SENSORS,
    WHEEL_MOTORS,
    MotorId,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
    Speeds,
)
from stairbot.inputs.config import RobotConfig

SLOW_FLOOR = 0.15
"""Slowest approach speed, as a fraction of the motor's maximum."""
WHEEL_BRAKE_ZONE = 0.075
"""Wheel turns a drive at the motor's top speed brakes over to a stop (7.5 mm
on the reference robot: 0.67 m/s², 0.15 s from 0.1 m/s)."""
LIFT_BRAKE_ZONE = 1.0
"""Lift turns a lift at the motor's top speed brakes over to a stop (2 mm on
the reference robot: 0.1 m/s², 0.2 s from 20 mm/s)."""
WHEEL_DONE = 0.002
"""A drive is done within this many wheel turns of its target (0.2 mm)."""
LIFT_DONE = 0.01
"""A lift is done within this many turns of its target (0.02 mm)."""
DIFF_SMOOTHING = 0.3
"""Weight of the newest reading in a smoothed difference of a sensor pair: it
averages the sensors' noise over a few ticks (calibration turns, standing rule)."""
TURN_SPEED = 0.15
"""Calibration turning speed of MWR/MWL, turns/s: slow, so noise cannot stop it early."""

# WHEEL_MOTORS, bound once for wheel_position (an enum's member is a slow look-up)
_MWF: Final = WHEEL_MOTORS[0]
_MWB: Final = WHEEL_MOTORS[1]
_MWR: Final = WHEEL_MOTORS[2]
_MWL: Final = WHEEL_MOTORS[3]


def wheel_position(snap: Snapshot) -> float:
    """The drive's odometer: the mean of the four wheel counters, turns."""
    # written out (asked every tick): sum()'s additions, in WHEEL_MOTORS' order
    m = snap.motors
    return (0.0 + m[_MWF].turns + m[_MWB].turns + m[_MWR].turns + m[_MWL].turns) / 4


def pair(snap: Snapshot, back: bool = False) -> tuple[SensorReading, SensorReading]:
    """(SFR, SFL), or (SBR, SBL) with ``back``."""
    right, left = BACK_SENSORS if back else FRONT_SENSORS
    return snap.sensors[right], snap.sensors[left]


def mean_distance(snap: Snapshot, back: bool = False) -> float:
    """Mean of the pair's distances (out-of-range readings count at their clamp)."""
    r, left = pair(snap, back)
    return (r.distance_m + left.distance_m) / 2.0


def far(reading: SensorReading, cfg: RobotConfig) -> bool:
    """The reading says "nothing ahead": at least LENGTH_OF_INFINITY, or out of
    range at the far end."""
    # cfg.algorithm's, not the config's property of the same name (asked every tick)
    return (reading.status is not SensorStatus.ERROR
            and reading.distance_m >= cfg.algorithm.LENGTH_OF_INFINITY)


def measurable(snap: Snapshot, cfg: RobotConfig) -> bool:
    """Both front sensors give a usable distance: status OK and closer than
    LENGTH_OF_INFINITY.  Not measurable: out of range (too near or nothing
    ahead), an error, or "nothing ahead"."""
    infinity = cfg.algorithm.LENGTH_OF_INFINITY  # (asked every tick: the reads inline)
    return all(r.status is _OK and r.distance_m < infinity for r in pair(snap))


def pair_difference(snap: Snapshot, cfg: RobotConfig, back: bool = False) -> float | None:
    """Left minus right reading of the pair (SFL − SFR, or SBL − SBR) when both
    give a usable distance (status OK, and for the front pair closer than
    LENGTH_OF_INFINITY); None otherwise."""
    sensors = snap.sensors  # (pair and SensorReading.ok, asked every tick: inline)
    r_id, l_id = BACK_SENSORS if back else FRONT_SENSORS
    r, left = sensors[r_id], sensors[l_id]
    if r.status is not _OK or left.status is not _OK:
        return None
    if not back and max(r.distance_m, left.distance_m) >= cfg.algorithm.LENGTH_OF_INFINITY:
        return None
    return left.distance_m - r.distance_m


def smooth(previous: float | None, newest: float) -> float:
    """One step of the exponential smoothing (DIFF_SMOOTHING) of a difference."""
    return newest if previous is None else previous + DIFF_SMOOTHING * (newest - previous)


def sensor_errors(snap: Snapshot, sensors: tuple[SensorId, ...]) -> list[SensorId]:
    """The sensors among ``sensors`` whose status is ERROR."""
    readings = snap.sensors
    return [s for s in sensors if readings[s].status is _ERROR]


_OK, _ERROR = SensorStatus.OK, SensorStatus.ERROR  # bound once: an enum's member is a slow look-up


def approach(vmax: float, remaining: float, brake_zone: float, tick: float) -> float:
    """Speed magnitude (per second) for ``remaining`` turns to go: ``vmax``
    until braking at a constant rate (``vmax`` to a stop over ``brake_zone``
    turns) must begin to stop on the target, then that braking curve; at
    least SLOW_FLOOR of ``vmax``, and never more than covers the remainder in
    one ``tick`` (no overshoot)."""
    # max(a, b) and min(a, b) written out (b if b > a else a; b if b < a else a):
    # the same answer, without the calls, asked for every moving motor every tick
    braking = vmax * math.sqrt((remaining if remaining > 0.0 else 0.0) / brake_zone)
    v = braking if braking < vmax else vmax
    floor = SLOW_FLOOR * vmax
    v = v if v > floor else floor
    cap = remaining / tick
    v = cap if cap < v else v
    return v if v > 0.0 else 0.0


def drive(cfg: RobotConfig, direction: int, remaining_turns: float) -> Speeds:
    """All four wheel motors at the same speed, ``direction`` +1 forward or -1
    back, braking to stop when ``remaining_turns`` are made."""
    v = direction * approach(cfg.motors.wheel_speed, remaining_turns, WHEEL_BRAKE_ZONE,
                             cfg.algorithm.tick)
    return {m: v for m in WHEEL_MOTORS}


def turn(direction: int, cfg: RobotConfig, fraction: float = 1.0) -> Speeds:
    """Turn in place on segment 2's wheels: +1 left (MWR forward, MWL back), at
    ``fraction`` of TURN_SPEED."""
    v = min(TURN_SPEED, cfg.motors.wheel_speed) * fraction
    return {MotorId.MWR: direction * v, MotorId.MWL: -direction * v}


def twist(snap: Snapshot) -> float:
    """The heading by the odometer, in wheel turns: half of MWR's counter less
    MWL's.  Driving moves both alike; turning in place moves them apart, by
    :func:`turn_yaw_rad` of this per radian."""
    return (snap.turns(MotorId.MWR) - snap.turns(MotorId.MWL)) / 2.0


def turn_yaw_rad(cfg: RobotConfig, wheel_turns: float) -> float:
    """Yaw made when MWR and MWL each make ``wheel_turns`` turns in opposite directions."""
    return wheel_turns * cfg.wheel_circumference / (cfg.geometry.track_width / 2.0)


def yaw_turns(cfg: RobotConfig, yaw_rad: float) -> float:
    """The turns MWR and MWL each make, in opposite directions, to turn
    ``yaw_rad`` (the inverse of :func:`turn_yaw_rad`)."""
    return yaw_rad * (cfg.geometry.track_width / 2.0) / cfg.wheel_circumference


def lift_to(cfg: RobotConfig, snap: Snapshot, motor: MotorId, target: float) -> float | None:
    """Speed that moves lift ``motor`` towards the absolute counter ``target``,
    or None when it is there."""
    delta = target - snap.motors[motor].turns
    if abs(delta) <= LIFT_DONE:
        return None
    v = approach(cfg.motors.lift_speed, abs(delta), LIFT_BRAKE_ZONE, cfg.algorithm.tick)
    return v if delta > 0 else -v


def lifts_to(cfg: RobotConfig, snap: Snapshot, targets: dict[MotorId, float]) -> Speeds | None:
    """Speeds that bring every lift in ``targets`` to its counter at once, or None
    when all are there."""
    out: dict[MotorId, float] = {}
    for motor, target in targets.items():
        v = lift_to(cfg, snap, motor, target)
        if v is not None:
            out[motor] = v
    return out or None
