"""The simulated robot behind the robot URL ``sim://``.

URL format: ``sim://`` (nothing else: the stairs come from the scenario, the
robot from the config, pacing from RobotOptions).

:class:`SimRobot` implements :class:`stairbot.hardware.Robot` on the pymunk side
view (:mod:`stairbot.fakes.world`), the top view (:mod:`stairbot.fakes.plan`)
and the sensor model (:mod:`stairbot.fakes.sensors`).  :class:`SimClock`
implements :class:`stairbot.hardware.Clock`: advancing it steps the physics,
and with pacing it is the only place in stairbot's simulation that sleeps.

Motors: commands beyond ``motors.wheel_speed`` / ``motors.lift_speed`` are
clamped.  Segment 2's wheels run at the mean of MWR and MWL in the side view;
their difference turns the robot about segment 2's centre at
(vR - vL) / track_width, but only while segments 1 and 3 are both lifted clear
of the ground (otherwise their wheels scrub and it does not turn).  Turn
counters come from the simulated wheels' rotation relative to their segment and
from the lifts' actual offsets (encoders), never from the commands.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from urllib.parse import urlsplit

from stairbot.fakes.plan import Plan
from stairbot.fakes.sensors import RangeSensor
from stairbot.fakes.world import World, WorldParams

from stairbot.config import RobotConfig
from stairbot.errors import RobotFellError, RobotUrlError
from stairbot.hardware import (
    LIFT_MOTORS,
    MotorId,
    MotorState,
    SensorId,
    SensorReading,
    Snapshot,
    Speeds,
)
from stairbot.robots import RobotOptions, RobotSession
from stairbot.scenario import Scenario

TURN_CLEARANCE = 0.003  # segments 1 and 3 must be this far off the ground to turn, m
Point = tuple[float, float]


@dataclass(frozen=True)
class Scene:
    """What the console draws, in world metres (x forward, y up; riser 1 at x=0)."""

    time_s: float
    stairs: tuple[Point, ...]  # the stairs' surface as one polyline
    segments: tuple[tuple[Point, ...], ...]  # segments 1, 2, 3: four corners each
    wheels: tuple[Point, ...]  # wheel centres: segment 1 rear, front, segment 2 ...
    wheel_radius: float
    yaw_deg: float
    lateral_m: float
    fell: bool


class SimRobot:
    """The simulated robot (see the module docstring)."""

    def __init__(self, config: RobotConfig, scenario: Scenario,
                 params: WorldParams | None = None) -> None:
        self.config = config
        self.scenario = scenario
        self.world = World(config, scenario, params)
        self.plan = Plan(scenario.width, scenario.side_wall, y=scenario.start.lateral,
                         yaw=math.radians(scenario.start.yaw_deg))
        self._start_y = self.plan.y
        s, n = config.sensors, scenario.sensors
        self.sensors = {
            sid: RangeSensor(sid, lo, hi, s.resolution, n.noise, n.seed, scenario.faults)
            for sid, lo, hi in (
                (SensorId.SFR, s.front_min_range, s.front_max_range),
                (SensorId.SFL, s.front_min_range, s.front_max_range),
                (SensorId.SBR, s.back_min_range, s.back_max_range),
                (SensorId.SBL, s.back_min_range, s.back_max_range),
            )
        }
        self._speeds: dict[MotorId, float] = dict.fromkeys(MotorId, 0.0)
        self._diff_turns = 0.0  # differential part of MWR (MWL gets minus this)
        self.closed = False

    # -- the Robot protocol ------------------------------------------------------
    def read(self) -> Snapshot:
        """Read every sensor and motor.  Raises RobotFellError once the world has
        detected instability."""
        w = self.world
        if w.fell:
            raise RobotFellError(w.fall_reason or "unstable")
        t = w.time
        front, back = self._front_truth(), self._back_truth()
        sensors: dict[SensorId, SensorReading] = {
            SensorId.SFR: self.sensors[SensorId.SFR].measure(front[0], t),
            SensorId.SFL: self.sensors[SensorId.SFL].measure(front[1], t),
            SensorId.SBR: self.sensors[SensorId.SBR].measure(back, t),
            SensorId.SBL: self.sensors[SensorId.SBL].measure(back, t),
        }
        return Snapshot(time_s=t, sensors=sensors, motors=self._motor_states(), health={})

    def command(self, speeds: Speeds) -> None:
        """Set every motor's speed in turns/s (clamped to the motor's limit)."""
        m = self.config.motors
        new = dict.fromkeys(MotorId, 0.0)
        for motor, value in speeds.items():
            limit = m.lift_speed if motor in LIFT_MOTORS else m.wheel_speed
            v = float(value)
            new[MotorId(motor)] = limit if v > limit else (-limit if v < -limit else v)
        self._apply(new)

    def stop_all(self) -> None:
        """Stop every motor at once; the lifts hold."""
        self._apply(dict.fromkeys(MotorId, 0.0))

    def diagnostics(self) -> dict[str, object]:
        """Simulation truth for summaries and the console."""
        w = self.world
        return {
            "sim_time_s": w.time,
            "pitch_deg": w.pitch_deg(),
            "max_pitch_deg": w.max_pitch_deg,
            "offset_m": self.offset_m(),
            "fell": w.fell,
            "fall_reason": w.fall_reason,
            "yaw_deg": math.degrees(self.plan.yaw),
            "lateral_m": self.plan.y,
            "x_m": w.centre_x(),
            "lift_front_m": w.lift_offset(0),
            "lift_back_m": w.lift_offset(1),
        }

    def close(self) -> None:
        """Stop every motor; the robot stays where it is."""
        self.stop_all()
        self.closed = True

    # -- simulation ----------------------------------------------------------------
    def advance(self, dt: float) -> None:
        """Simulate ``dt`` seconds with the motors as last commanded."""
        w = self.world
        sp = self._speeds
        diff = (sp[MotorId.MWR] - sp[MotorId.MWL]) / 2.0  # turns/s
        turning = diff != 0.0 and (w.clear_of_ground(0, TURN_CLEARANCE)
                                   and w.clear_of_ground(2, TURN_CLEARANCE))
        x0, t0 = w.centre_x(), w.time
        w.advance(dt)
        elapsed = w.time - t0
        self.plan.move(w.centre_x() - x0)
        if diff != 0.0:
            self._diff_turns += diff * elapsed
            if turning:
                v = 2.0 * diff * self.config.wheel_circumference  # vR - vL, m/s
                self.plan.turn(v / self.config.geometry.track_width * elapsed)

    def offset_m(self) -> float:
        """Top-view distance of segment 2's centre from where it started."""
        return math.hypot(self.world.centre_x() - self.world.start_x,
                          self.plan.y - self._start_y)

    def scene(self) -> Scene:
        """The stairs and the robot's pose, for drawing."""
        w = self.world
        return Scene(
            time_s=w.time,
            stairs=tuple(w.outline),
            segments=tuple(tuple(w.segment_corners(i)) for i in range(3)),
            wheels=tuple((float(b.position.x), float(b.position.y)) for b in w.all_wheels),
            wheel_radius=w.radius,
            yaw_deg=math.degrees(self.plan.yaw),
            lateral_m=self.plan.y,
            fell=w.fell,
        )

    # -- internals -------------------------------------------------------------------
    def _apply(self, speeds: dict[MotorId, float]) -> None:
        self._speeds = speeds
        w = self.world
        w.set_wheel_speed(0, speeds[MotorId.MWF])
        w.set_wheel_speed(1, (speeds[MotorId.MWR] + speeds[MotorId.MWL]) / 2.0)
        w.set_wheel_speed(2, speeds[MotorId.MWB])
        per_turn = self.config.motors.lift_travel_per_turn
        w.set_lift_speed(0, speeds[MotorId.MTF] * per_turn)
        w.set_lift_speed(1, speeds[MotorId.MTB] * per_turn)

    def _motor_states(self) -> dict[MotorId, MotorState]:
        w = self.world
        per_turn = self.config.motors.lift_travel_per_turn
        mean, mean_speed = w.wheel_turns(1), w.wheel_speed(1)
        d = self._diff_turns
        ds = (self._speeds[MotorId.MWR] - self._speeds[MotorId.MWL]) / 2.0
        return {
            MotorId.MWF: MotorState(w.wheel_turns(0), w.wheel_speed(0)),
            MotorId.MWB: MotorState(w.wheel_turns(2), w.wheel_speed(2)),
            MotorId.MWR: MotorState(mean + d, mean_speed + ds),
            MotorId.MWL: MotorState(mean - d, mean_speed - ds),
            MotorId.MTF: MotorState(w.lift_offset(0) / per_turn, self._speeds[MotorId.MTF]),
            MotorId.MTB: MotorState(w.lift_offset(1) / per_turn, self._speeds[MotorId.MTB]),
        }

    def _front_truth(self) -> tuple[float | None, float | None]:
        """True distances seen by SFR and SFL (None: nothing within range)."""
        w, s, g = self.world, self.config.sensors, self.config.geometry
        seg1 = w.segments[0]
        mount_local = (w.lengths[0] / 2, s.front_height - g.wheel_radius)
        mount = seg1.local_to_world(mount_local)
        reach = s.front_max_range * 1.05
        ahead = seg1.local_to_world((mount_local[0] + reach, mount_local[1]))
        hit = w.ray((mount.x, mount.y), (ahead.x, ahead.y))
        slant = 1.0 / max(math.cos(seg1.angle), 1e-6)
        hit_dx = None if hit is None else hit[0] - mount.x
        # the mount's distance ahead of segment 2's centre, along the robot
        forward = float(w.segments[1].world_to_local(mount).x)
        lat = s.front_lateral
        return (self.plan.front_distance(forward, -lat, hit_dx, slant),
                self.plan.front_distance(forward, lat, hit_dx, slant))

    def _back_truth(self) -> float | None:
        """True distance seen by SBR/SBL straight down from segment 3."""
        w, s, g = self.world, self.config.sensors, self.config.geometry
        seg3 = w.segments[2]
        local = (-w.lengths[2] / 2 + s.back_from_rear, s.back_height - g.wheel_radius)
        mount = seg3.local_to_world(local)
        below = seg3.local_to_world((local[0], local[1] - s.back_max_range * 1.05))
        hit = w.ray((mount.x, mount.y), (below.x, below.y))
        if hit is None:
            return None
        return math.hypot(hit[0] - mount.x, hit[1] - mount.y)


class SimClock:
    """Simulated time: ``advance(dt)`` steps the robot's physics by ``dt``.

    With a ``time_scale`` (simulated seconds per wall second; 1.0 = real time)
    it sleeps so that simulated time tracks the wall clock at that rate; without
    one it runs as fast as the machine allows and never sleeps.
    """

    def __init__(self, robot: SimRobot, time_scale: float | None = None,
                 monotonic: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        self.robot = robot
        self.time_scale = time_scale
        self._monotonic = monotonic
        self._sleep = sleep
        self._wall0 = monotonic()
        self._sim0 = robot.world.time

    def now(self) -> float:
        return self.robot.world.time

    def advance(self, dt: float) -> None:
        self.robot.advance(dt)
        if self.time_scale is not None:
            due = self._wall0 + (self.robot.world.time - self._sim0) / self.time_scale
            delay = due - self._monotonic()
            if delay > 0:
                self._sleep(delay)
            elif delay < -1.0:  # far behind (a pause, a slow machine): do not race
                self._wall0 -= delay

    def set_time_scale(self, time_scale: float | None) -> None:
        """Change the pacing (None: as fast as possible) from now on."""
        self.time_scale = time_scale
        self._wall0 = self._monotonic()
        self._sim0 = self.robot.world.time


def open_sim_robot(url: str, config: RobotConfig, scenario: Scenario,
                   options: RobotOptions) -> RobotSession:
    """Open ``sim://``: a fresh simulated robot at the scenario's start pose.
    Raises RobotUrlError for anything but ``sim://``."""
    parts = urlsplit(url)
    if parts.scheme != "sim" or parts.netloc or parts.path or parts.query or parts.fragment:
        raise RobotUrlError(url, None, "the simulated robot takes no host, path or "
                            "options; allowed: sim://")
    robot = SimRobot(config, scenario)
    scale = options.time_scale
    if scale is None and options.realtime:
        scale = 1.0
    clock = SimClock(robot, scale)
    return RobotSession(robot=robot, clock=clock, url=url, simulated=True, sim=robot)
