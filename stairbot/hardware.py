"""The small hardware interface the controller talks to, and the clock.

Everything the algorithm knows of the robot comes through :class:`Robot`:
four distance sensors with a status each (six on a robot with the side pair),
six motors with a turn counter each.
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
from types import MappingProxyType
from typing import Literal, Protocol, runtime_checkable

from stairbot.events import EventSink


class SensorId(StrEnum):
    SFR = "SFR"  # segment 1, front right, looking forward
    SFL = "SFL"  # segment 1, front left, looking forward
    SBR = "SBR"  # segment 3, back right, looking down
    SBL = "SBL"  # segment 3, back left, looking down
    SSR = "SSR"  # segment 3, right side, looking right, parallel to the floor (optional)
    SSL = "SSL"  # segment 3, left side, looking left, parallel to the floor (optional)


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
SIDE_SENSORS: tuple[SensorId, ...] = (SensorId.SSR, SensorId.SSL)
"""The side pair, for quarter-turn landings (the seed's extension 1): only a
robot whose config has one (``[sensors] side_model``) reads them; a snapshot
of any other carries the four sensors without them."""
BASE_SENSORS: tuple[SensorId, ...] = FRONT_SENSORS + BACK_SENSORS
"""The four sensors every robot has."""


class SensorStatus(StrEnum):
    OK = "ok"
    OUT_OF_RANGE = "out_of_range"  # no target within range, a return too weak to range, or
    # a target closer than the minimum
    ERROR = "error"  # the sensor reports a fault; the distance means nothing


_STATUS_OK = SensorStatus.OK  # bound once: an enum's member is a slow look-up


@dataclass(frozen=True, slots=True)
class SensorReading:
    """One distance reading.  With OUT_OF_RANGE the distance is clamped to the
    sensor's minimum (target too near) or maximum (nothing within range)."""

    distance_m: float
    status: SensorStatus = SensorStatus.OK
    age_s: float = 0.0
    """How long before the snapshot's time the sensor took this measurement
    (the board's own count: a sensor repeats its last value between
    measurements).  Perception does not use a reading older than its sensor
    allows."""

    @property
    def ok(self) -> bool:
        return self.status is _STATUS_OK


@dataclass(frozen=True, slots=True)
class MotorState:
    """One motor's telemetry: its turn counter, present speed and any fault."""

    turns: float
    speed_tps: float = 0.0
    fault: str | None = None


@dataclass(frozen=True, slots=True)
class Imu:
    """The sensor board's inertial unit (it rides in segment 2): attitude and
    rates of segment 2.  Pitch is positive nose up (the front higher than the
    back), roll positive right side down; rates in degrees per second."""

    pitch_deg: float
    roll_deg: float
    pitch_rate_dps: float = 0.0
    roll_rate_dps: float = 0.0
    age_s: float = 0.0
    """How long before the snapshot's time it was measured."""


@dataclass(frozen=True, slots=True)
class Snapshot:
    """Everything read from the robot at one control tick."""

    time_s: float
    sensors: Mapping[SensorId, SensorReading]
    motors: Mapping[MotorId, MotorState]
    health: Mapping[str, float] = field(default_factory=dict)
    imu: Imu | None = None
    """None: the robot has no IMU (or it did not answer); the supervisor then
    cannot watch the tilt and says so."""

    def turns(self, motor: MotorId) -> float:
        return self.motors[motor].turns


Speeds = Mapping[MotorId, float]
"""Motor speed commands in turns/s; a motor left out is commanded to 0."""

ZERO_SPEEDS: Speeds = MappingProxyType(dict.fromkeys(MotorId, 0.0))
"""Every motor at 0 (lifts hold), read-only: share it, never copy it."""


@runtime_checkable
class Robot(Protocol):
    """A robot the controller can drive: the simulation, or boards on a wire.

    Every robot (sim://, serial://, can://, a third party's) implements all of
    it; tests/test_robot_conformance.py holds them to it.  Optional abilities
    are the small protocols below, checked with ``isinstance``."""

    def read(self) -> Snapshot:
        """Read every sensor and motor.  Raises HardwareError (LinkLostError,
        RobotFellError) when the robot cannot be read or is no longer safe."""
        ...

    def command(self, speeds: Speeds) -> None:
        """Set every motor's speed (turns/s); motors left out get 0.  While the
        e-stop is latched every motor stays stopped whatever is asked."""
        ...

    def stop_all(self) -> None:
        """Stop every motor at once; lifts hold.  Not latched.  Never raises."""
        ...

    def estop(self) -> None:
        """Emergency stop: every motor stops at once, the lifts hold, and the
        stop is latched (``command`` moves nothing) until :meth:`clear`.
        ``read`` still works while latched (the operator watches the sensors).
        Never raises, not even on a lost link or after ``close``."""
        ...

    def clear(self) -> None:
        """Clear the e-stop latch (and any latch the boards hold).  Moves
        nothing by itself: motion needs a new ``command``."""
        ...

    @property
    def estopped(self) -> bool:
        """True while the e-stop is latched (as far as the host knows)."""
        ...

    def diagnostics(self) -> dict[str, object]:
        """Extra facts for the summary and the console (link health)."""
        ...

    def close(self) -> None:
        """Stop every motor and release the robot.  Closing twice is harmless."""
        ...


@dataclass(frozen=True, slots=True)
class TruthMargins:
    """The least of each margin a simulation measured over a run, from its
    physics (:mod:`stairbot.fakes.margin_watch` defines each); None: never
    measured."""

    stability_m: float | None
    """How far the centre of mass stood inside its loaded wheels' span, m."""
    edge_m: float | None
    """How far a loaded wheel's centre stood past its tread's nosing, m."""
    stroke_m: float | None
    """The lift travel left at the more extended lift, m."""


@dataclass(frozen=True, slots=True)
class Truth:
    """What only a simulation knows of itself: for summaries, sweeps and the
    console's picture, never for the controller."""

    fell: bool
    fall_reason: str | None
    pitch_deg: float | None
    max_pitch_deg: float | None
    offset_m: float | None
    """Distance of segment 2's centre from where it started, seen from above
    (in flight 1's frame)."""
    clear_of_stairs_m: float | None = None
    """How far the robot's front face stands before the first riser (negative:
    over the stairs): a descent from the top has reached the floor."""
    wall_contact: str | None = None
    """The first time the robot's footprint seen from above (its three segments
    end to end, ``track_width`` + 2 cm wide) reached more than 3 mm into a wall
    (side walls, a wall at the top, a quarter-turn landing's walls) or into a
    riser of a landing's second flight standing higher than the segment's
    underside there: which segment, what and when, e.g. "segment 1 against the
    landing's far wall at 212.40 s".  None: never, or a robot that cannot tell.
    The simulation's physics holds only the robot's centre line against the
    stairs of its side view, so it lets the robot through; a sweep should judge
    a contact unsafe."""
    flight: int = 1
    """The flight whose frame the side view (``Scene``) is in: 1, or 2 while the
    robot stands turned more than 45 degrees towards a quarter-turn landing's
    second flight, or on it."""
    flight1_x_m: float | None = None
    """Segment 2's centre in flight 1's frame, seen from above: along flight 1,
    from its first riser (+ = towards the risers), whatever ``flight``."""
    flight1_y_m: float | None = None
    """... across flight 1, from its centre line (+ = left)."""
    flight1_yaw_deg: float | None = None
    """The robot's heading from straight up flight 1, degrees (+ = turned left)."""
    margins: TruthMargins | None = None
    """The least margins so far; None: a robot that cannot tell."""


@runtime_checkable
class HasTruth(Protocol):
    """A simulated robot (sim://, or fake boards in lockstep) that can tell the
    truth about itself."""

    def truth(self) -> Truth:
        ...


@runtime_checkable
class HasAttitude(Protocol):
    """A robot that can read its IMU outside a run, whatever its latches (the
    boards): what a resume looks at before it clears anything."""

    def attitude(self) -> Imu | None:
        """The IMU now; None when the robot has none, or it has no valid reading."""
        ...


@runtime_checkable
class HasIdentity(Protocol):
    """A robot that can say which boards it is (serial://, can://, and the
    console's watched robot around any robot): what a journal keeps and a
    resume compares."""

    def identity(self) -> dict[str, dict[str, int]] | None:
        """Each board's serial number, uptime (ms) and boot id, by board name;
        None for a robot that has no boards."""
        ...


@runtime_checkable
class HoldsLatches(Protocol):
    """A robot whose boards keep their latches from one host to the next
    (serial://, can://): a resume says it clears them, and clears them."""

    @property
    def latched(self) -> Mapping[int, int]:
        """The latch flags each board held when the host opened it, by board."""
        ...


@runtime_checkable
class EstopsFromAnyThread(Protocol):
    """A robot whose ``estop()`` may be called from any thread at any moment,
    without waiting for a lock a read may hold (the boards' driver, whose
    reads retry on a lossy wire): the console's e-stop key calls it at once."""

    estop_any_thread: Literal[True]


Point = tuple[float, float]


@dataclass(frozen=True, slots=True)
class Scene:
    """A simulation's side view, for the console's picture: world metres, x
    forward (towards the stairs), y up, riser 1 at x = 0."""

    time_s: float
    stairs: tuple[Point, ...]
    """The stairs' surface as one polyline."""
    segments: tuple[tuple[Point, ...], ...]
    """Segments 1, 2, 3 (front to back), each a closed outline."""
    wheels: tuple[Point, ...]
    """Wheel centres, segment 1's first."""
    wheel_radius: float
    yaw_deg: float
    lateral_m: float
    fell: bool
    flight2: tuple[float, int] | None = None
    """None: the side view is along the stairs' first flight.  On a
    quarter-turn landing's second flight (the side view along it), ``(x_mid,
    sign)``: a pose (x, y, yaw) of this view is (x_mid − sign·y, sign·x, yaw +
    sign·90°) in the first flight's frame (sign +1: the second flight leaves
    to the left)."""


@runtime_checkable
class HasScene(Protocol):
    """A simulation that can draw itself (sim://): the console's picture."""

    def scene(self) -> Scene:
        ...


@runtime_checkable
class ReportsEvents(Protocol):
    """A robot that tells its own events (a wired robot's link health)."""

    def attach_sink(self, sink: EventSink) -> None:
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
