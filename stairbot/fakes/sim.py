"""The simulated robot behind the robot URL ``sim://``.

URL format: ``sim://`` (nothing else: the stairs come from the scenario, the
robot from the config, pacing from RobotOptions).

:class:`SimRobot` implements :class:`stairbot.hardware.Robot` on the pymunk side
view (:mod:`stairbot.fakes.world`), the top view (:mod:`stairbot.fakes.plan`)
and the sensor models (:mod:`stairbot.fakes.sensor_model`, one preset per
sensor pair from the config's ``[sensors] front_model`` / ``back_model``; the
cones' rays are cast by :mod:`stairbot.fakes.beams`).  :class:`SimClock`
implements :class:`stairbot.hardware.Clock`: advancing it steps the physics,
and with pacing it is the only place in stairbot's simulation that sleeps.

Motors: commands beyond ``motors.wheel_speed`` / ``motors.lift_speed`` are
clamped.  Segment 2's wheels run at the mean of MWR and MWL in the side view;
their difference turns the robot about segment 2's centre at
(vR - vL) / track_width, but only while segments 1 and 3 are both lifted clear
of the ground (otherwise their wheels scrub and it does not turn).  Turn
counters come from the simulated wheels' rotation relative to their segment and
from the lifts' actual offsets (encoders), not from the commands; the one
exception is the differential part of MWR/MWL, which the side view cannot roll:
it integrates the commanded difference (the wheels spin whether or not the
robot turns).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from urllib.parse import urlsplit

from stairbot.config import RobotConfig
from stairbot.errors import RobotFellError, RobotUrlError
from stairbot.fakes.beams import down_hits, front_hits, total_weight
from stairbot.fakes.plan import Plan
from stairbot.fakes.sensor_model import ModelSensor, combine
from stairbot.fakes.sensor_presets import model_for
from stairbot.fakes.world import World, WorldParams
from stairbot.hardware import (
    LIFT_MOTORS,
    ZERO_SPEEDS,
    MotorId,
    MotorState,
    Scene,
    SensorId,
    SensorReading,
    Snapshot,
    Speeds,
    Truth,
)
from stairbot.robots import RobotOptions, RobotSession
from stairbot.scenario import Scenario, load_scenario

TURN_CLEARANCE = 0.003  # segments 1 and 3 must be this far off the ground to turn, m


class SimRobot:
    """The simulated robot (see the module docstring): a Robot, with the
    capabilities HasTruth (``truth()``) and HasScene (``scene()``)."""

    def __init__(self, config: RobotConfig, scenario: Scenario,
                 params: WorldParams | None = None) -> None:
        self.config = config
        self.scenario = scenario
        self.world = World(config, scenario, params)
        self.plan = Plan(scenario.width, scenario.side_wall, y=scenario.start.lateral,
                         yaw=math.radians(scenario.start.yaw_deg))
        self._start_y = self.plan.y
        s, n = config.sensors, scenario.sensors
        self.front_model, self.back_model = model_for(s, back=False), model_for(s, back=True)
        self.sensors = {
            sid: ModelSensor(sid, model, lo, hi, s.resolution, n.noise, n.seed, scenario.faults)
            for sid, model, lo, hi in (
                (SensorId.SFR, self.front_model, s.front_min_range, s.front_max_range),
                (SensorId.SFL, self.front_model, s.front_min_range, s.front_max_range),
                (SensorId.SBR, self.back_model, s.back_min_range, s.back_max_range),
                (SensorId.SBL, self.back_model, s.back_min_range, s.back_max_range),
            )
        }
        self._front_weight = total_weight(self.front_model.cone)
        self._back_weight = total_weight(self.back_model.fan)
        m = config.motors
        self._limits = {mid: m.lift_speed if mid in LIFT_MOTORS else m.wheel_speed
                        for mid in MotorId}
        self._speeds = dict(ZERO_SPEEDS)
        self._diff_turns = 0.0  # differential part of MWR (MWL gets minus this)
        self._diff_speed = 0.0  # ... and its speed over the last advance, turns/s
        self._lift_turns = [0.0, 0.0]
        # Wheel encoders count the wheels' travel along the robot's heading; the
        # side view moves only its projection on the flight's axis (see _apply).
        self._wheel_seen = [self.world.wheel_state(i)[0] for i in range(3)]
        self._wheel_turns = [0.0, 0.0, 0.0]
        self._wheel_tps = [0.0, 0.0, 0.0]
        self._lift_tps = [0.0, 0.0]  # measured over the last advance
        self._snap: Snapshot | None = None
        self._snap_at = -1
        r = config.geometry.wheel_radius
        # sensor mounts in their segment's frame (origin: centre of the axle line)
        self._front_mount = (self.world.lengths[0] / 2, s.front_height - r,
                             (self.front_model.max_range or s.front_max_range) * 1.05)
        self._back_mount = (-self.world.lengths[2] / 2 + s.back_from_rear,
                            s.back_height - r,
                            (self.back_model.max_range or s.back_max_range) * 1.05)
        self.closed = False
        self._estopped = False

    # -- the Robot protocol ------------------------------------------------------
    def read(self) -> Snapshot:
        """Read every sensor and motor.  Raises RobotFellError once the world has
        detected instability.  Reading twice with no simulated time between gives
        the same snapshot (a sensor samples once per physics state)."""
        w = self.world
        if w.fell:
            raise RobotFellError(w.fall_reason or "unstable")
        if self._snap is not None and self._snap_at == w.steps_done:
            return self._snap
        t = w.time
        sfr, sfl = self._front_readings(t)
        sbr, sbl = self._back_readings(t)
        snap = Snapshot(time_s=t, sensors={
            SensorId.SFR: sfr, SensorId.SFL: sfl, SensorId.SBR: sbr, SensorId.SBL: sbl,
        }, motors=self._motor_states(), health={})
        self._snap, self._snap_at = snap, w.steps_done
        return snap

    def command(self, speeds: Speeds) -> None:
        """Set every motor's speed in turns/s (clamped to the motor's limit; a
        speed that is not a finite number stops that motor).  While the e-stop
        is latched every motor stays stopped."""
        new = dict(ZERO_SPEEDS)
        if self._estopped:
            self._apply(new)
            return
        limits = self._limits
        for motor, value in speeds.items():
            limit = limits[motor]
            v = float(value)
            if v != v or v in (math.inf, -math.inf):
                v = 0.0
            new[motor] = limit if v > limit else (-limit if v < -limit else v)
        self._apply(new)

    def stop_all(self) -> None:
        """Stop every motor at once; the lifts hold.  Never raises (not even
        after a fall or close)."""
        self._apply(dict(ZERO_SPEEDS))

    def estop(self) -> None:
        """Stop every motor and latch: commands move nothing until clear().
        Reading goes on.  Never raises."""
        self._estopped = True
        self.stop_all()

    def clear(self) -> None:
        """Clear the e-stop latch; nothing moves until the next command."""
        self._estopped = False

    @property
    def estopped(self) -> bool:
        return self._estopped

    def diagnostics(self) -> dict[str, object]:
        """The simulation's pose, for a person reading it (a run's fell, pitch
        and offset come from :meth:`truth`)."""
        w = self.world
        return {
            "sim_time_s": w.time,
            "yaw_deg": math.degrees(self.plan.yaw),
            "lateral_m": self.plan.y,
            "x_m": w.centre_x(),
            "lift_front_m": w.lift_offset(0),
            "lift_back_m": w.lift_offset(1),
        }

    def close(self) -> None:
        """Stop every motor; the robot stays where it is.  Closing again is
        harmless."""
        self.stop_all()
        self.closed = True

    # -- capabilities: HasTruth, HasScene -------------------------------------------
    def truth(self) -> Truth:
        """Whether the robot fell (and why), its pitch now and the most it
        pitched, and how far segment 2 is from where it started."""
        w = self.world
        return Truth(fell=w.fell, fall_reason=w.fall_reason, pitch_deg=w.pitch_deg(),
                     max_pitch_deg=w.max_pitch_deg, offset_m=self.offset_m())

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
        if elapsed <= 0.0:
            return
        self.plan.move(w.centre_x() - x0)
        along = self._along()
        for i in range(3):
            seen = w.wheel_state(i)[0]
            turned = (seen - self._wheel_seen[i]) / along
            self._wheel_seen[i] = seen
            self._wheel_turns[i] += turned
            self._wheel_tps[i] = turned / elapsed
        self._diff_speed = diff
        if diff != 0.0:
            self._diff_turns += diff * elapsed
            if turning:
                v = 2.0 * diff * self.config.wheel_circumference  # vR - vL, m/s
                self.plan.turn(v / self.config.geometry.track_width * elapsed)
        per_turn = self.config.motors.lift_travel_per_turn
        for i in (0, 1):
            turns = w.lift_offset(i) / per_turn
            self._lift_tps[i] = (turns - self._lift_turns[i]) / elapsed
            self._lift_turns[i] = turns

    def offset_m(self) -> float:
        """Top-view distance of segment 2's centre from where it started."""
        return math.hypot(self.world.centre_x() - self.world.start_x,
                          self.plan.y - self._start_y)

    # -- internals -------------------------------------------------------------------
    def _apply(self, speeds: dict[MotorId, float]) -> None:
        self._speeds = speeds
        w = self.world
        # The side view is the flight's axis: a robot yawed by psi driving at v
        # closes on the risers at v cos(psi) and drifts sideways at v sin(psi)
        # (Plan.move), never faster than its wheels.
        along = self._along()
        w.set_wheel_speed(0, speeds[MotorId.MWF] * along)
        w.set_wheel_speed(1, (speeds[MotorId.MWR] + speeds[MotorId.MWL]) / 2.0 * along)
        w.set_wheel_speed(2, speeds[MotorId.MWB] * along)
        per_turn = self.config.motors.lift_travel_per_turn
        w.set_lift_speed(0, speeds[MotorId.MTF] * per_turn)
        w.set_lift_speed(1, speeds[MotorId.MTB] * per_turn)

    def _along(self) -> float:
        """cos(yaw): the share of the robot's travel along the flight's axis."""
        return max(0.05, math.cos(self.plan.yaw))

    def _motor_states(self) -> dict[MotorId, MotorState]:
        w = self.world
        per_turn = self.config.motors.lift_travel_per_turn
        turns, tps = self._wheel_turns, self._wheel_tps
        mean, mean_speed = turns[1], tps[1]
        d, ds = self._diff_turns, self._diff_speed
        return {
            MotorId.MWF: MotorState(turns[0], tps[0]),
            MotorId.MWB: MotorState(turns[2], tps[2]),
            MotorId.MWR: MotorState(mean + d, mean_speed + ds),
            MotorId.MWL: MotorState(mean - d, mean_speed - ds),
            MotorId.MTF: MotorState(w.lift_offset(0) / per_turn, self._lift_tps[0]),
            MotorId.MTB: MotorState(w.lift_offset(1) / per_turn, self._lift_tps[1]),
        }

    def _front_readings(self, t: float) -> tuple[SensorReading, SensorReading]:
        """What SFR and SFL report at ``t``: one ray each for a single-ray model,
        else their cones, cast only when a measurement is due."""
        right, left = self.sensors[SensorId.SFR], self.sensors[SensorId.SFL]
        model = self.front_model
        if model.single_ray:
            sfr, sfl = self._front_truth()
            return right.measure(sfr, t), left.measure(sfl, t)
        if right.due(t) or left.due(t):
            mx, my, a1, _c, _s, forward = self._front_origin()
            lat = self.config.sensors.front_lateral
            hits = front_hits(self.world, self.plan, model, (mx, my), a1, forward,
                              (-lat, lat), self._front_mount[2])
            for sensor, seen in ((right, hits[0]), (left, hits[1])):
                if sensor.due(t):
                    sensor.sample(combine(model, seen, self._front_weight), t)
        return right.reading(t), left.reading(t)

    def _back_readings(self, t: float) -> tuple[SensorReading, SensorReading]:
        """What SBR and SBL report at ``t`` (see _front_readings)."""
        right, left = self.sensors[SensorId.SBR], self.sensors[SensorId.SBL]
        model = self.back_model
        if model.single_ray:
            sbr, sbl = self._back_truth()
            return right.measure(sbr, t), left.measure(sbl, t)
        if right.due(t) or left.due(t):
            w = self.world
            (xr, xl), my, a3, _c, _s, reach = self._back_origins()
            seen_r = down_hits(w, model, (xr, my), a3, reach)
            seen_l = seen_r if xl == xr else down_hits(w, model, (xl, my), a3, reach)
            for sensor, seen in ((right, seen_r), (left, seen_l)):
                if sensor.due(t):
                    sensor.sample(combine(model, seen, self._back_weight), t)
        return right.reading(t), left.reading(t)

    def _front_origin(self) -> tuple[float, float, float, float, float, float]:
        """The front mount in the side view (x, y), segment 1's angle, its cos
        and sin, and the mount's distance ahead of segment 2's centre."""
        w = self.world
        lx, ly, _reach = self._front_mount
        x1, y1, a1 = w.pose(0)
        c, s = math.cos(a1), math.sin(a1)
        mx, my = x1 + c * lx - s * ly, y1 + s * lx + c * ly
        # the mount's distance ahead of segment 2's centre, along the robot
        x2, y2, a2 = w.pose(1)
        forward = math.cos(a2) * (mx - x2) + math.sin(a2) * (my - y2)
        return mx, my, a1, c, s, forward

    def _front_truth(self) -> tuple[float | None, float | None]:
        """True distances seen by SFR and SFL (None: nothing within range)."""
        w = self.world
        reach = self._front_mount[2]
        mx, my, _a1, c, s, forward = self._front_origin()
        hit = w.ray((mx, my), (mx + c * reach, my + s * reach))
        hit_dx = None if hit is None else hit[0] - mx
        slant = 1.0 / max(c, 1e-6)
        lat = self.config.sensors.front_lateral
        front_distance = self.plan.front_distance
        return (front_distance(forward, -lat, hit_dx, slant),
                front_distance(forward, lat, hit_dx, slant))

    def _back_truth(self) -> tuple[float | None, float | None]:
        """True distances seen by SBR and SBL, looking down from segment 3.  Turned
        by a yaw, the two stand at different x (over a nosing they may disagree)."""
        (xr, xl), my, _a3, c, s, reach = self._back_origins()
        d = self._down(xr, my, c, s, reach)
        return d, (d if xl == xr else self._down(xl, my, c, s, reach))

    def _back_origins(self) -> tuple[tuple[float, float], float, float, float, float, float]:
        """The side-view x of SBR and SBL, their height, segment 3's angle, its
        cos and sin, and the rays' reach.  Turned by a yaw, the two stand at
        different x."""
        w = self.world
        lx, ly, reach = self._back_mount
        x3, y3, a3 = w.pose(2)
        c, s = math.cos(a3), math.sin(a3)
        mx, my = x3 + c * lx - s * ly, y3 + s * lx + c * ly
        yaw = self.plan.yaw
        if yaw == 0.0:
            return (mx, mx), my, a3, c, s, reach
        # top view: the mount sits `behind` along the robot and +-lateral across it
        x2 = w.pose(1)[0]
        behind = mx - x2
        shift = behind * (math.cos(yaw) - 1.0)
        lat = self.config.sensors.back_lateral * math.sin(yaw)
        return (mx + shift + lat, mx + shift - lat), my, a3, c, s, reach

    def _down(self, mx: float, my: float, c: float, s: float, reach: float) -> float | None:
        hit = self.world.ray((mx, my), (mx + s * reach, my - c * reach))
        if hit is None:
            return None
        return math.hypot(hit[0] - mx, hit[1] - my)


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


def open_sim_robot(url: str, config: RobotConfig, options: RobotOptions) -> RobotSession:
    """Open ``sim://``: a fresh simulated robot at the start pose of
    ``options.world`` (the default scenario if none).  Raises RobotUrlError
    for anything but ``sim://``."""
    parts = urlsplit(url)
    if parts.scheme != "sim" or parts.netloc or parts.path or parts.query or parts.fragment:
        raise RobotUrlError(url, None, "the simulated robot takes no host, path or "
                            "options; allowed: sim://")
    robot = SimRobot(config, options.world or load_scenario())
    scale = options.time_scale
    if scale is None and options.realtime:
        scale = 1.0
    clock = SimClock(robot, scale)
    return RobotSession(robot=robot, clock=clock, url=url, simulated=True, sim=robot)
