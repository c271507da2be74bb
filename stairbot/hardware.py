"""The small hardware interface the controller talks to, and the clock.

Everything the algorithm knows of the robot comes through :class:`Robot`:
four distance sensors with a status each, six motors with a turn counter each.
Conventions (the same for the simulation, the drivers and the boards):

* wheel motors (MWF, MWB, MWR, MWL): positive speed drives the robot forward
  (towards the stairs); turns count up when driving forward.
* lift motors (MTF, MTB): positive speed raises the end segment (1 for MTF,
  3 for MTB) relative to segment 2; turns count up while raising.  With the
  end segment resting on a support, raising it relative to segment 2 lowers
  segment 2, and vice versa.  Speed 0 holds the lift where it is.
* speeds are in turns per second; distances in metres; times in seconds.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Protocol, runtime_checkable


class SensorId(StrEnum):
    SFR = "SFR"  # segment 1, front right, looking forward
    SFL = "SFL"  # segment 1, front left, looking forward
    SBR = "SBR"  # segment 3, back right, looking down
    SBL = "SBL"  # segment 3, back left, looking down


class MotorId(StrEnum):
    MWF = "MWF"  # wheels of segment 1
    MWB = "MWB"  # wheels of segment 3
    MWR = "MWR"  # right wheels of segment 2
    MWL = "MWL"  # left wheels of segment 2
    MTF = "MTF"  # lift: segment 1 relative to segment 2
    MTB = "MTB"  # lift: segment 3 relative to segment 2


WHEEL_MOTORS: tuple[MotorId, ...] = (MotorId.MWF, MotorId.MWB, MotorId.MWR, MotorId.MWL)
LIFT_MOTORS: tuple[MotorId, ...] = (MotorId.MTF, MotorId.MTB)
FRONT_SENSORS: tuple[SensorId, ...] = (SensorId.SFR, SensorId.SFL)
BACK_SENSORS: tuple[SensorId, ...] = (SensorId.SBR, SensorId.SBL)


class SensorStatus(StrEnum):
    OK = "ok"
    OUT_OF_RANGE = "out_of_range"  # no target within range (or closer than the minimum)
    ERROR = "error"  # the sensor reports a fault; the distance means nothing


@dataclass(frozen=True, slots=True)
class SensorReading:
    """One distance reading.  With OUT_OF_RANGE the distance is clamped to the
    sensor's minimum (target too near) or maximum (nothing within range)."""

    distance_m: float
    status: SensorStatus = SensorStatus.OK

    @property
    def ok(self) -> bool:
        return self.status is SensorStatus.OK


@dataclass(frozen=True, slots=True)
class MotorState:
    """One motor's telemetry: its turn counter, present speed and any fault."""

    turns: float
    speed_tps: float = 0.0
    fault: str | None = None


@dataclass(frozen=True, slots=True)
class Snapshot:
    """Everything read from the robot at one control tick."""

    time_s: float
    sensors: Mapping[SensorId, SensorReading]
    motors: Mapping[MotorId, MotorState]
    health: Mapping[str, float] = field(default_factory=dict)

    def turns(self, motor: MotorId) -> float:
        return self.motors[motor].turns


Speeds = Mapping[MotorId, float]
"""Motor speed commands in turns/s; a motor left out is commanded to 0."""


@runtime_checkable
class Robot(Protocol):
    """A robot the controller can drive: the simulation, or boards on a wire."""

    def read(self) -> Snapshot:
        """Read every sensor and motor.  Raises HardwareError (LinkLostError,
        RobotFellError) when the robot cannot be read or is no longer safe."""
        ...

    def command(self, speeds: Speeds) -> None:
        """Set every motor's speed (turns/s); motors left out get 0."""
        ...

    def stop_all(self) -> None:
        """Stop every motor at once; lifts hold.  Never raises."""
        ...

    def diagnostics(self) -> dict[str, object]:
        """Extra facts for the summary and the console (sim truth, link health)."""
        ...

    def close(self) -> None:
        """Stop every motor and release the robot."""
        ...


@runtime_checkable
class Clock(Protocol):
    """The controller's clock.  A simulated clock advances the physics; a wall
    clock sleeps.  The core never sleeps on its own."""

    def now(self) -> float:
        ...

    def advance(self, dt: float) -> None:
        """Let ``dt`` seconds pass (simulate them, or wait for them)."""
        ...
