"""The simulated robot behind the robot URL ``sim://``.

URL format: ``sim://`` (nothing else: the stairs come from the scenario, the
robot from the config, pacing from RobotOptions).

:class:`SimRobot` implements :class:`stairbot.hardware.Robot` on the pymunk side
view (:mod:`stairbot.fakes.world`), the top view (:mod:`stairbot.fakes.plan`)
and the sensor board (:mod:`stairbot.fakes.sim_sensors`: the four distance
sensors through their models, and the IMU in segment 2 -- pitch from the
pymunk body, roll 0 because a side view cannot roll).  :class:`SimClock`
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

Quarter-turn landings (:mod:`stairbot.fakes.landing`): once per advance the
robot, turned past 45 degrees on the landing, may move to the other flight's
frame (the side view rebuilt, the bodies shifted along x, the top view
re-framed: counters and readings carry on); and its footprint seen from
above is checked against the walls and the second flight's risers, which the
side view's physics does not stop it at (``truth()``'s ``wall_contact``).
``truth()`` tells the frame and the pose in flight 1's frame.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from urllib.parse import urlsplit

from stairbot.errors import RobotFellError, RobotUrlError
from stairbot.fakes.landing import FOOTPRINT_MARGIN, Stairwell
from stairbot.fakes.plan import Plan
from stairbot.fakes.sim_sensors import SimImu, SimSensors
from stairbot.fakes.world import World, WorldParams
from stairbot.hardware import (
    LIFT_MOTORS,
    ZERO_SPEEDS,
    MotorId,
    MotorState,
    Scene,
    Snapshot,
    Speeds,
    Truth,
    TruthMargins,
)
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, load_scenario
from stairbot.readings import motor_state, snapshot
from stairbot.run.robots import RobotOptions, RobotSession

TURN_CLEARANCE = 0.003  # segments 1 and 3 must be this far off the ground to turn, m

# bound once: an enum's member is a slow look-up, and every tick names each motor
_MWF, _MWB, _MWR, _MWL, _MTF, _MTB = (MotorId.MWF, MotorId.MWB, MotorId.MWR, MotorId.MWL,
                                      MotorId.MTF, MotorId.MTB)
_ZEROS: dict[MotorId, float] = dict(ZERO_SPEEDS)  # copied by every command (a dict copies fast)


def motor_limits(config: RobotConfig) -> dict[MotorId, float]:
    """Each motor's speed limit, turns/s: a command beyond it is clamped."""
    mc = config.motors
    return {mid: mc.lift_speed if mid in LIFT_MOTORS else mc.wheel_speed for mid in MotorId}


class SimRobot:
    """The simulated robot (see the module docstring): a Robot, with the
    capabilities HasTruth (``truth()``) and HasScene (``scene()``)."""

    def __init__(self, config: RobotConfig, scenario: Scenario,
                 params: WorldParams | None = None) -> None:
        self.config = config
        self.scenario = scenario
        self.world = World(config, scenario, params)
        self.well = Stairwell(scenario)
        self.plan = Plan(scenario.width, scenario.side_wall, y=scenario.start.lateral,
                         yaw=math.radians(scenario.start.yaw_deg), x=self.world.centre_x(),
                         walls=self.well.walls(1))
        self._start_y = self.plan.y
        self.board = SimSensors(config, scenario, self.world, self.plan, self.well)
        self.well.footprint(self.world.lengths, config.geometry.track_width + FOOTPRINT_MARGIN)
        self.wall_contact: str | None = None
        """The first contact of the footprint with a wall (see Truth.wall_contact)."""
        self._imu = SimImu(self.world)
        self._limits = motor_limits(config)
        self._per_turn = config.motors.lift_travel_per_turn
        self._speeds = dict(ZERO_SPEEDS)
        self._applied_along = math.nan  # cos(yaw) when the world's motors were last set
        self._diff_turns = 0.0  # differential part of MWR (MWL gets minus this)
        self._diff_speed = 0.0  # ... and its speed over the last advance, turns/s
        self._lift_turns = [0.0, 0.0]
        # Wheel encoders count the wheels' travel along the robot's heading; the
        # side view moves only its projection on the flight's axis (see _apply).
        self._wheel_seen = [self.world.wheel_turns(i) for i in range(3)]
        self._wheel_turns = [0.0, 0.0, 0.0]
        self._wheel_tps = [0.0, 0.0, 0.0]
        self._lift_tps = [0.0, 0.0]  # measured over the last advance
        self._snap: Snapshot | None = None
        self._snap_at = -1
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
        snap = snapshot(w.time, self.board.read(w.time), self._motor_states(), {},
                        self._imu.read())
        self._snap, self._snap_at = snap, w.steps_done
        return snap

    def command(self, speeds: Speeds) -> None:
        """Set every motor's speed in turns/s (clamped to the motor's limit; a
        speed that is not a finite number stops that motor).  While the e-stop
        is latched every motor stays stopped."""
        new = _ZEROS.copy()
        if self._estopped:
            self._apply(new)
            return
        limits = self._limits
        for motor, value in speeds.items():
            limit = limits[motor]
            v = float(value)
            if v - v != 0.0:  # NaN or infinite
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
        and offset come from :meth:`truth`): in flight 1's frame."""
        w = self.world
        x, y, yaw = self.flight1_pose()
        return {
            "sim_time_s": w.time,
            "yaw_deg": math.degrees(yaw),
            "lateral_m": y,
            "x_m": x,
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
        pitched, how far segment 2 is from where it started, how far it stands
        before the stairs, its first contact with a wall, the frame it is in
        its pose in flight 1's frame, and the least margins so far."""
        w = self.world
        x, y, yaw = self.flight1_pose()
        return Truth(fell=w.fell, fall_reason=w.fall_reason, pitch_deg=w.pitch_deg(),
                     max_pitch_deg=w.max_pitch_deg, offset_m=self.offset_m(),
                     clear_of_stairs_m=self.clear_of_stairs_m(),
                     wall_contact=self.wall_contact, flight=self.well.flight,
                     flight1_x_m=x, flight1_y_m=y, flight1_yaw_deg=math.degrees(yaw),
                     margins=TruthMargins(w.margins.stability_m, w.margins.edge_m,
                                          w.margins.stroke_m))

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
            flight2=(self.well.x_mid, self.well.sign) if self.well.flight == 2 else None,
        )

    # -- simulation ----------------------------------------------------------------
    def advance(self, dt: float) -> None:
        """Simulate ``dt`` seconds with the motors as last commanded."""
        w = self.world
        sp = self._speeds
        diff = (sp[_MWR] - sp[_MWL]) / 2.0  # turns/s
        turning = diff != 0.0 and (w.clear_of_ground(0, TURN_CLEARANCE)
                                   and w.clear_of_ground(2, TURN_CLEARANCE))
        x0, t0 = w.centre_x(), w.time
        w.advance(dt)
        elapsed = w.time - t0
        if elapsed <= 0.0:
            return
        px, _py, _pa, seen, lifts = w.state()
        self.plan.move(px[1] - x0)
        along = self._along()
        seen_turns, wheel_turns, wheel_tps = self._wheel_seen, self._wheel_turns, self._wheel_tps
        for i in (0, 1, 2):
            turned = (seen[i] - seen_turns[i]) / along
            seen_turns[i] = seen[i]
            wheel_turns[i] += turned
            wheel_tps[i] = turned / elapsed
        self._diff_speed = diff
        if diff != 0.0:
            self._diff_turns += diff * elapsed
            if turning:
                v = 2.0 * diff * self.config.wheel_circumference  # vR - vL, m/s
                self.plan.turn(v / self.config.geometry.track_width * elapsed)
        per_turn, lift_turns, lift_tps = self._per_turn, self._lift_turns, self._lift_tps
        for i in (0, 1):
            turns = lifts[i] / per_turn
            lift_tps[i] = (turns - lift_turns[i]) / elapsed
            lift_turns[i] = turns
        well = self.well
        if well.turns and well.switch(w, self.plan):
            self._apply(self._speeds)  # the share of travel along the new frame's axis
        if self.wall_contact is None and well.watches():
            self._watch_walls()

    def _watch_walls(self) -> None:
        """Record the footprint's first contact with a wall or a riser of a
        landing's second flight (fakes/landing.py, Stairwell.contact)."""
        x, y, yaw = self.flight1_pose()
        met = self.well.contact(self.world, x, y, yaw)
        if met is not None:
            segment, what = met
            self.wall_contact = f"segment {segment + 1} against {what} at {self.world.time:.2f} s"

    def flight1_pose(self) -> tuple[float, float, float]:
        """Segment 2's centre and the heading (radians) in flight 1's frame."""
        return self.well.in_flight1(self.world.centre_x(), self.plan.y, self.plan.yaw)

    def offset_m(self) -> float:
        """Top-view distance of segment 2's centre from where it started (in
        flight 1's frame)."""
        x, y, _yaw = self.flight1_pose()
        return math.hypot(x - self.world.start_x, y - self._start_y)

    def clear_of_stairs_m(self) -> float:
        """How far segment 1's front face stands before riser 1, along flight 1
        (negative: over the stairs).  In flight 2's frame: segment 2's centre in
        flight 1's frame plus the front face's distance ahead of it along the
        robot, as flight 1's side view counts it (continuous across the switch)."""
        w = self.world
        clear = w.clear_of_stairs_m()
        if self.well.flight == 1:
            return clear
        ahead = -clear - w.centre_x()
        return -(self.flight1_pose()[0] + ahead)

    # -- internals -------------------------------------------------------------------
    def _apply(self, speeds: dict[MotorId, float]) -> None:
        # The side view is the flight's axis: a robot yawed by psi driving at v
        # closes on the risers at v cos(psi) and drifts sideways at v sin(psi)
        # (Plan.move), never faster than its wheels.
        along = self._along()
        same = speeds == self._speeds and along == self._applied_along
        self._speeds, self._applied_along = speeds, along
        if same:
            return  # the world's motors run as they were set
        w = self.world
        w.set_wheel_speed(0, speeds[_MWF] * along)
        w.set_wheel_speed(1, (speeds[_MWR] + speeds[_MWL]) / 2.0 * along)
        w.set_wheel_speed(2, speeds[_MWB] * along)
        per_turn = self._per_turn
        w.set_lift_speed(0, speeds[_MTF] * per_turn)
        w.set_lift_speed(1, speeds[_MTB] * per_turn)

    def _along(self) -> float:
        """cos(yaw): the share of the robot's travel along the flight's axis
        (the Plan's, worked out when the yaw changes)."""
        return max(0.05, self.plan.yaw_trig()[0])

    def _motor_states(self) -> dict[MotorId, MotorState]:
        lifts = self.world.state()[4]
        per_turn, lift_tps = self._per_turn, self._lift_tps
        turns, tps = self._wheel_turns, self._wheel_tps
        mean, mean_speed = turns[1], tps[1]
        d, ds = self._diff_turns, self._diff_speed
        return {
            _MWF: motor_state(turns[0], tps[0]),
            _MWB: motor_state(turns[2], tps[2]),
            _MWR: motor_state(mean + d, mean_speed + ds),
            _MWL: motor_state(mean - d, mean_speed - ds),
            _MTF: motor_state(lifts[0] / per_turn, lift_tps[0]),
            _MTB: motor_state(lifts[1] / per_turn, lift_tps[1]),
        }


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
