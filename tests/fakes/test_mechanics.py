"""The simulated mechanics, driven open loop through the agreed physical
reading of the algorithm (brief): one step up, then back down, before any
controller exists.  Every motion is decided from sensor readings and turn
counters, as the controller will."""

from __future__ import annotations

import math
from collections.abc import Callable

import pytest

from stairbot.control.robot_config import load_config
from stairbot.errors import RobotFellError
from stairbot.fakes.sim import SimClock, SimRobot
from stairbot.hardware import MotorId, SensorId, Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, load_scenario

F, B, R, L = MotorId.MWF, MotorId.MWB, MotorId.MWR, MotorId.MWL
MTF, MTB = MotorId.MTF, MotorId.MTB
IDEAL = load_config("ideal")  # the mechanics, driven on one exact ray per sensor


class OpenLoop:
    """A bare-hands driver of the simulated robot: one motion at a time."""

    def __init__(self, config: RobotConfig, scenario: Scenario) -> None:
        self.cfg = config
        self.robot = SimRobot(config, scenario)
        self.clock = SimClock(self.robot)
        self.tick = config.algorithm.tick

    def snap(self) -> Snapshot:
        return self.robot.read()

    def front(self) -> float:
        s = self.snap().sensors
        return min(s[SensorId.SFR].distance_m, s[SensorId.SFL].distance_m)

    def back(self) -> float:
        s = self.snap().sensors
        return max(s[SensorId.SBR].distance_m, s[SensorId.SBL].distance_m)

    def run_until(self, speeds: dict[MotorId, float], done: Callable[[], bool],
                  limit_s: float = 60.0) -> None:
        t0 = self.clock.now()
        self.robot.command(speeds)
        while not done():
            assert self.clock.now() - t0 < limit_s, f"motion {speeds} did not finish"
            self.clock.advance(self.tick)
            self.robot.command(speeds)
        self.robot.stop_all()
        self.clock.advance(self.tick)

    def drive(self, metres: float) -> None:
        """All wheels forward (or back) by ``metres`` of segment 2's wheel turns."""
        target = self.snap().turns(R) + self.cfg.wheel_turns(metres)
        top = self.cfg.motors.wheel_speed
        t0 = self.clock.now()
        while abs(rem := target - self.snap().turns(R)) > 0.005:
            assert self.clock.now() - t0 < 60.0, "drive did not finish"
            v = max(-top, min(top, rem / self.tick))  # land on the target, not past it
            self.robot.command({F: v, B: v, R: v, L: v})
            self.clock.advance(self.tick)
        self.robot.stop_all()
        self.clock.advance(self.tick)

    def lifts(self, **targets: float) -> None:
        """Move MTF/MTB (keyword mtf=, mtb=) to counter targets at full speed."""
        ids = {"mtf": MTF, "mtb": MTB}

        def remaining() -> dict[MotorId, float]:
            snap = self.snap()
            return {ids[k]: t - snap.turns(ids[k]) for k, t in targets.items()}

        speed = self.cfg.motors.lift_speed
        t0 = self.clock.now()
        while True:
            rem = remaining()
            if all(abs(r) < 0.05 for r in rem.values()):
                break
            assert self.clock.now() - t0 < 60.0
            # slow down within the last tick's travel so the counters land on target
            self.robot.command({m: max(-speed, min(speed, r / self.tick)) for m, r in rem.items()})
            self.clock.advance(self.tick)
        self.robot.stop_all()
        self.clock.advance(self.tick)

    # -- the agreed physical reading of the algorithm, one step -----------------
    def ascend_one_step(self) -> dict[str, float]:
        """Ascent 2-9 on the first step; returns the figures a controller stores."""
        cfg, a = self.cfg, self.cfg.algorithm
        fwd = {F: 1.0, B: 1.0, R: 1.0, L: 1.0}
        self.run_until(fwd, lambda: self.front() <= a.SAFE_DISTANCE_IN_FRONT_OF_STEP)
        self.drive(a.SAFE_DISTANCE_IN_FRONT_OF_STEP - a.approach_gap)
        self.run_until({MTF: 10.0},
                       lambda: self.front() >= cfg.LENGTH_OF_A_ROBOT + a.SAFE_LENGTH)
        length_of_next_step = self.front()
        self.lifts(mtf=self.snap().turns(MTF) + cfg.initial_number_of_vertical_turns)
        h = self.snap().turns(MTF)
        self.drive(cfg.LENGTH_OF_FIRST_MODULE)
        self.lifts(mtf=0.0, mtb=-h)
        self.drive(cfg.LENGTH_OF_SECOND_MODULE)
        self.lifts(mtb=0.0)
        tab = self.front()
        self.run_until(fwd, lambda: self.front() <= length_of_next_step - cfg.LENGTH_OF_A_ROBOT)
        return {"h": h, "tab": tab, "length_of_next_step": length_of_next_step}

    def descend_one_step(self, tab: float) -> float:
        """Descent 1-6 from the tread above; returns the turns of the step height."""
        cfg = self.cfg
        back = {F: -1.0, B: -1.0, R: -1.0, L: -1.0}
        self.run_until(back, lambda: self.front() >= tab)
        self.run_until({MTB: -10.0}, lambda: self.back() <= cfg.BACK_CLEARANCE)
        h = -self.snap().turns(MTB)
        self.run_until(back, lambda: self.front() >= tab + cfg.LENGTH_OF_SECOND_MODULE)
        self.lifts(mtf=h, mtb=0.0)
        self.run_until(back, lambda: self.front() >= tab + cfg.LENGTH_OF_SECOND_MODULE
                       + cfg.LENGTH_OF_FIRST_MODULE)
        self.lifts(mtf=0.0)
        return h

    def segment_spans(self) -> list[tuple[float, float, float]]:
        """(rear x, front x, lowest wheel bottom y) of each segment, world truth."""
        w = self.robot.world
        out = []
        for i in range(3):
            xs = [p[0] for p in w.segment_corners(i)]
            bottom = min(wh.position.y for wh in w.wheels[i]) - w.radius
            out.append((min(xs), max(xs), float(bottom)))
        return out


@pytest.fixture(scope="module")
def climbed() -> tuple[OpenLoop, dict[str, float]]:
    drv = OpenLoop(IDEAL, load_scenario())
    figures = drv.ascend_one_step()
    return drv, figures


def test_one_step_up_puts_all_three_segments_on_the_tread(
        climbed: tuple[OpenLoop, dict[str, float]]) -> None:
    drv, figures = climbed
    step = drv.robot.scenario.steps[0]
    truth = drv.robot.truth()
    assert truth.fell is False
    assert truth.max_pitch_deg is not None
    assert truth.max_pitch_deg < 6.0  # ~3 deg expected while tipping onto segment 1
    rise_turns = drv.cfg.lift_turns(step.rise)
    assert rise_turns < figures["h"] < rise_turns + drv.cfg.lift_turns(0.015)
    for rear, front, bottom in drv.segment_spans():
        assert 0.0 < front <= step.tread
        assert rear > -0.015  # the rear may overhang the nosing by the approach gap only
        assert bottom == pytest.approx(step.rise, abs=0.003)
    # the whole robot stands level on the tread
    assert truth.pitch_deg is not None and abs(truth.pitch_deg) < 1.0


def test_one_step_down_returns_to_the_floor(
        climbed: tuple[OpenLoop, dict[str, float]]) -> None:
    drv, figures = climbed
    h = drv.descend_one_step(figures["tab"])
    step = drv.robot.scenario.steps[0]
    assert h == pytest.approx(drv.cfg.lift_turns(step.rise), abs=drv.cfg.lift_turns(0.004))
    truth = drv.robot.truth()
    assert truth.fell is False
    assert truth.max_pitch_deg is not None and truth.max_pitch_deg < 6.0
    for _rear, front, bottom in drv.segment_spans():
        assert front < 0.0  # before riser 1
        assert bottom == pytest.approx(0.0, abs=0.003)
    snap = drv.snap()
    assert abs(snap.turns(MTF)) < 0.5 and abs(snap.turns(MTB)) < 0.5


def test_backing_off_the_top_edge_with_lifts_level_falls() -> None:
    drv = OpenLoop(IDEAL, load_scenario())
    drv.ascend_one_step()
    back = {F: -1.0, B: -1.0, R: -1.0, L: -1.0}
    with pytest.raises(RobotFellError):
        drv.run_until(back, lambda: drv.snap() is None, limit_s=10.0)
    truth = drv.robot.truth()
    assert truth.fell is True
    assert isinstance(truth.fall_reason, str) and truth.fall_reason
    drv.robot.stop_all()  # never raises, even after a fall


def test_turned_over_a_nosing_the_back_sensors_disagree() -> None:
    drv = OpenLoop(IDEAL, load_scenario())
    drv.ascend_one_step()  # the rear of segment 3 ends over riser 1's nosing
    w, s = drv.robot.world, drv.cfg.sensors
    rear = min(p[0] for p in w.segment_corners(2))
    mount_x = rear + s.back_from_rear
    # turn (in the top view) just enough that SBL's spot crosses the nosing's edge
    drv.robot.plan.yaw = math.asin(min(1.0, (abs(mount_x) + 0.01) / s.back_lateral))
    if mount_x < 0:
        drv.robot.plan.yaw = -drv.robot.plan.yaw  # from the floor side onto the tread
    drv.clock.advance(drv.tick)
    snap = drv.snap().sensors
    readings = sorted((snap[SensorId.SBR].distance_m, snap[SensorId.SBL].distance_m))
    rise = drv.robot.scenario.steps[0].rise
    assert readings[0] == pytest.approx(drv.cfg.BACK_CLEARANCE, abs=0.003)
    assert readings[1] == pytest.approx(drv.cfg.BACK_CLEARANCE + rise, abs=0.005)
