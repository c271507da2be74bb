"""Descent 2 on a slow back pair: segment 3 is lowered to the floor, not
pushed into it.  The pair's filtered reading stands for measurements taken
a while ago (an HC-SR04 pair: 25 ms of latency, then the median's majority
of a window at one measurement in 60 ms); counted as if it were now, the
lift reaches the floor still near full speed, and the rest the reading says
is left drives it on, lifting segment 2 off its supports."""

from __future__ import annotations

import json
import math

import pytest
from kinematic import KinematicRobot

from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.work import LowerThirdWork
from stairbot.control.robot_config import load_config
from stairbot.hardware import BACK_SENSORS, MotorId, SensorReading, Snapshot

SONAR = load_config("sonar")


class SlowBackPair(KinematicRobot):
    """The kinematic robot with its back pair measuring as the config's
    sensor does: every ``period_s`` (at its whole multiples), published
    ``latency_s`` later, the board saying how old it is."""

    def __post_init__(self) -> None:
        super().__post_init__()
        spec = self.cfg.sensors.spec(True)
        self.period, self.latency = spec.period_s, spec.latency_s
        self.next_at = 0.0
        self.pending: list[tuple[float, float, dict]] = []  # (published at, taken at, readings)
        self.current: tuple[float, dict] | None = None

    def read(self) -> Snapshot:
        snap = super().read()
        if self.t >= self.next_at - 1e-9:
            self.next_at = (math.floor(self.t / self.period + 1e-9) + 1) * self.period
            taken = {s: snap.sensors[s] for s in BACK_SENSORS}
            if self.current is None:
                self.current = (self.t, taken)
            else:
                self.pending.append((self.t + self.latency, self.t, taken))
        while self.pending and self.pending[0][0] <= self.t + 1e-9:
            _, at, taken = self.pending.pop(0)
            self.current = (at, taken)
        assert self.current is not None
        at, taken = self.current
        sensors = dict(snap.sensors)
        for s in BACK_SENSORS:
            r = taken[s]
            sensors[s] = SensorReading(r.distance_m, r.status, self.t - at)
        return Snapshot(snap.time_s, sensors, snap.motors, snap.health, snap.imu)

    def push_m(self) -> float:
        """How far segment 3, standing on the floor, has lifted segment 2
        above where segments 1 and 2 would carry it."""
        inset = self.cfg.geometry.wheel_inset
        offs = self.offsets()
        ground = []
        for i in range(3):
            rear, front = self.segment_span(i)
            ground.append(max(self.floor(rear + inset), self.floor(front - inset)))
        carried = max(ground[0] - offs[0], ground[1] - offs[1])
        return max(0.0, ground[2] - offs[2] - carried)


def test_lowering_segment_3_on_a_slow_back_pair_stops_at_the_floor() -> None:
    """The lift is counted as having lowered segment 3 while the pair's
    measurements came through: it slows down before the floor and stops
    there (within a millimetre), not the pair's lag at full speed (3.5 mm)
    into it; on a real robot that push pitches segment 2 nose down, segment
    3's back and its sensors rise, they read longer, and the lift went on
    pushing to the tilt stop."""
    ctrl = Controller(SONAR)
    robot = SlowBackPair(SONAR, steps=[(0.10, 0.37)], distance=0.4)
    tick = SONAR.algorithm.tick
    lowered = False
    most = 0.0
    while not ctrl.finished and robot.t < 400.0:
        speeds = ctrl.tick(robot.read())
        if ctrl.phase is Phase.DESCENT_LOWER_THIRD:
            lowered = True
        elif lowered:
            break  # descent 2 is over: where segment 3 stopped is what counts
        robot.command(speeds)
        robot.advance(tick)
        if lowered:
            most = max(most, robot.push_m())
    assert lowered and not ctrl.finished
    assert most < 0.001
    # the rise, as h (the noise-free pair still reads to a millimetre)
    assert ctrl.context.number_of_turns_for_step_height * SONAR.motors.lift_travel_per_turn \
        == pytest.approx(0.10, abs=0.0015)
    assert robot.counters[MotorId.MTB] * SONAR.motors.lift_travel_per_turn \
        == pytest.approx(-0.10, abs=0.0015)


def test_the_lowering_s_recent_turns_survive_a_journal_round_trip() -> None:
    """A host killed while segment 3 is lowered resumes with the turns the
    lag still needs: the work's (time, MTB) pairs come back as they were."""
    ctx = Context()
    ctx.work = LowerThirdWork(mtb_recent=[(10.0, 3.25), (10.02, 3.2)])
    back = Context.from_dict(json.loads(json.dumps(ctx.to_dict())))
    assert isinstance(back.work, LowerThirdWork)
    assert back.work.mtb_recent == [(10.0, 3.25), (10.02, 3.2)]
