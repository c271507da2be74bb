"""A kinematic stand-in for the robot, for the controller's tests: no physics,
just geometry, so every phase can be walked quickly and exactly.

Side view: stairs as risers at x = R_k (riser 1 at x = 0) with heights H_k;
the robot's segments sit as low as their supports allow (segment 2 at the
highest of "ground under segment s minus lift offset of s"), so a segment can
be cantilevered.  Top view: a yaw, which turns the front sensors' beams.
Motors are perfect: counters integrate the commanded speeds.  Sensors: range
limits, resolution, optional seeded noise, and scripted faults.
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from dataclasses import dataclass, field

from stairbot.control.algorithm.controller import Controller
from stairbot.hardware import (
    LIFT_MOTORS,
    Imu,
    MotorId,
    MotorState,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
)
from stairbot.inputs.config import RobotConfig

WALL_HEIGHT = 10.0


@dataclass
class Fault:
    sensor: SensorId
    start: float
    end: float = math.inf
    offset: float = 0.0
    error: bool = False
    freeze: bool = False  # the board repeats the last measurement, and says how old it is


@dataclass
class KinematicRobot:
    cfg: RobotConfig
    steps: list[tuple[float, float]] = field(default_factory=lambda: [(0.17, 0.28)] * 5)
    top: str = "landing"  # or "wall"
    distance: float = 0.5  # front face to riser 1
    yaw_deg: float = 0.0
    noise: float = 0.0
    seed: int = 1
    faults: list[Fault] = field(default_factory=list)
    back_offset: float = 0.0  # added to SBR/SBL: a floor further down than it is
    motor_faults: dict[MotorId, str] = field(default_factory=dict)
    jammed: set[MotorId] = field(default_factory=set)  # commanded, but do not turn
    front_override: Callable[[KinematicRobot], tuple[float, float]] | None = None
    # the segments stand level (no physics): the IMU reads 0 unless a test says otherwise
    imu: Imu | None = field(default_factory=lambda: Imu(0.0, 0.0))

    def __post_init__(self) -> None:
        g = self.cfg.geometry
        self.t = 0.0
        self.front_x = -self.distance
        self.yaw = math.radians(self.yaw_deg)
        self.counters: dict[MotorId, float] = dict.fromkeys(MotorId, 0.0)
        self.speeds: dict[MotorId, float] = dict.fromkeys(MotorId, 0.0)
        self.rng = random.Random(self.seed)
        self._taken: dict[SensorId, tuple[SensorReading, float]] = {}
        self.risers: list[tuple[float, float]] = []  # (x, height of the tread after it)
        x = height = 0.0
        for rise, tread in self.steps:
            height += rise
            self.risers.append((x, height))
            x += tread
        if self.top == "wall":
            self.risers.append((x, height + WALL_HEIGHT))
        self.lengths = (g.LENGTH_OF_FIRST_MODULE, g.LENGTH_OF_SECOND_MODULE,
                        g.LENGTH_OF_THIRD_MODULE)
        self.start_front_x = self.front_x

    # -- geometry ------------------------------------------------------------------
    def floor(self, x: float) -> float:
        h = 0.0
        for rx, height in self.risers:
            if x >= rx:
                h = height
        return h

    def segment_span(self, i: int) -> tuple[float, float]:
        front = self.front_x - sum(self.lengths[:i])
        return front - self.lengths[i], front

    def offsets(self) -> tuple[float, float, float]:
        lead = self.cfg.motors.lift_travel_per_turn
        return self.counters[MotorId.MTF] * lead, 0.0, self.counters[MotorId.MTB] * lead

    def heights(self) -> tuple[float, float, float]:
        """Contact-line height of segments 1, 2, 3."""
        inset = self.cfg.geometry.wheel_inset
        offs = self.offsets()
        ground = []
        for i in range(3):
            rear, front = self.segment_span(i)
            ground.append(max(self.floor(rear + inset), self.floor(front - inset)))
        z2 = max(ground[i] - offs[i] for i in range(3))
        return z2 + offs[0], z2, z2 + offs[2]

    def _beam(self, lateral: float, height: float) -> float | None:
        d_centre = self.lengths[0] + self.lengths[1] / 2
        centre = self.front_x - d_centre
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        x = centre + d_centre * c - lateral * s
        for rx, top in self.risers:
            if rx > x and top > height:
                return (rx - x) / c
        return None

    def true_front(self) -> tuple[float | None, float | None]:
        if self.front_override is not None:
            return self.front_override(self)
        beam = self.heights()[0] + self.cfg.sensors.front_height
        lat = self.cfg.sensors.front_lateral
        return self._beam(-lat, beam), self._beam(lat, beam)

    def true_back(self) -> float:
        rear, _ = self.segment_span(2)
        x = rear + self.cfg.sensors.back_from_rear
        return self.heights()[2] + self.cfg.sensors.back_height - self.floor(x) + self.back_offset

    # -- the Robot protocol ----------------------------------------------------------
    def _measure(self, sid: SensorId, d: float | None, lo: float, hi: float) -> SensorReading:
        offset = 0.0
        for f in self.faults:
            if f.sensor is sid and f.start <= self.t < f.end:
                if f.freeze and sid in self._taken:
                    last, at = self._taken[sid]
                    return SensorReading(last.distance_m, last.status, self.t - at)
                if f.error:
                    return SensorReading(lo, SensorStatus.ERROR)
                offset += f.offset
        if d is None:
            return SensorReading(hi, SensorStatus.OUT_OF_RANGE)
        d += offset + (self.rng.gauss(0.0, self.noise) if self.noise else 0.0)
        res = self.cfg.sensors.resolution
        if res:
            d = round(d / res) * res
        if d < lo:
            return SensorReading(lo, SensorStatus.OUT_OF_RANGE)
        if d > hi:
            return SensorReading(hi, SensorStatus.OUT_OF_RANGE)
        return SensorReading(d)

    def _fresh(self, sid: SensorId, d: float | None, lo: float, hi: float) -> SensorReading:
        reading = self._measure(sid, d, lo, hi)
        if reading.age_s == 0.0:
            self._taken[sid] = (reading, self.t)
        return reading

    def read(self) -> Snapshot:
        s = self.cfg.sensors
        sfr, sfl = self.true_front()
        back = self.true_back()
        sensors = {
            SensorId.SFR: self._fresh(SensorId.SFR, sfr, s.front_min_range, s.front_max_range),
            SensorId.SFL: self._fresh(SensorId.SFL, sfl, s.front_min_range, s.front_max_range),
            SensorId.SBR: self._fresh(SensorId.SBR, back, s.back_min_range, s.back_max_range),
            SensorId.SBL: self._fresh(SensorId.SBL, back, s.back_min_range, s.back_max_range),
        }
        motors = {m: MotorState(self.counters[m], self.speeds[m], self.motor_faults.get(m))
                  for m in MotorId}
        return Snapshot(self.t, sensors, motors, imu=self.imu)

    def command(self, speeds: dict[MotorId, float]) -> None:
        self.speeds = {m: float(speeds.get(m, 0.0)) for m in MotorId}

    def advance(self, dt: float) -> None:
        cfg = self.cfg
        sp = {m: 0.0 if m in self.jammed else v for m, v in self.speeds.items()}
        limit = cfg.MAX_OF_VERTICAL_TURNS
        for m in MotorId:
            self.counters[m] += sp[m] * dt
            if m in LIFT_MOTORS:
                self.counters[m] = max(-limit, min(limit, self.counters[m]))
        forward = (sp[MotorId.MWR] + sp[MotorId.MWL]) / 2 * cfg.wheel_circumference * dt
        self.front_x += forward * math.cos(self.yaw)
        diff = (sp[MotorId.MWR] - sp[MotorId.MWL]) * cfg.wheel_circumference
        self.yaw += diff / cfg.geometry.track_width * dt
        self.t += dt


def run(ctrl: Controller, robot: KinematicRobot, max_time: float = 3000.0,
        until: Callable[[Controller], bool] | None = None) -> list[dict[MotorId, float]]:
    """Tick ``ctrl`` against ``robot`` until it finishes (or ``until`` says so);
    returns every command sent."""
    sent = []
    tick = robot.cfg.algorithm.tick
    while not ctrl.finished and robot.t < max_time:
        if until is not None and until(ctrl):
            break
        speeds = ctrl.tick(robot.read())
        sent.append(speeds)
        robot.command(speeds)
        robot.advance(tick)
    return sent
