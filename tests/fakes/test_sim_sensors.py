"""The simulated sensor board: the IMU reports segment 2's pitch and pitch rate
(roll 0: a side view cannot roll), and each distance reading carries its
sensor model's age (0 and shared for the ideal preset).  The config's tilt
limits stop the robot before the simulation counts a fall."""

from __future__ import annotations

from dataclasses import replace

import msgspec
import msgspec.inspect as mi
import pytest

from stairbot.control.robot_config import load_config
from stairbot.fakes.sim import SimClock, SimRobot
from stairbot.fakes.world import WorldParams
from stairbot.hardware import SensorId
from stairbot.inputs.scenario import parse_scenario
from stairbot.inputs.sections import Safety
from stairbot.run.robots import RobotSession
from stairbot.run.runner import run

CFG = load_config("ideal")  # one level ray, fresh at every read
TICK = CFG.algorithm.tick
ONE_STEP = parse_scenario("""
[stairs]
count = 1
[start]
distance = 0.2
""", "<one step>")


def test_the_imu_is_segment_2s_pitch_and_rate_and_never_rolls() -> None:
    robot = SimRobot(CFG, ONE_STEP)
    seen: list[tuple[float, float, float]] = []

    def on_tick(_ctl: object, snap: object) -> None:
        imu = robot.read().imu
        assert imu is not None and imu.age_s == 0.0
        assert imu.roll_deg == 0.0 and imu.roll_rate_dps == 0.0
        assert imu.pitch_deg == robot.world.pitch_deg(1)  # the IMU rides in segment 2
        # its rate is the mean since the last reading, as a gyro's low-pass
        # gives it: the change of pitch over the tick (not one physics step's
        # angular velocity, which a contact's impulse spikes)
        if seen:
            t0, p0, _ = seen[-1]
            assert imu.pitch_rate_dps == pytest.approx(
                (imu.pitch_deg - p0) / (robot.world.time - t0), abs=1e-9)
        seen.append((robot.world.time, imu.pitch_deg, imu.pitch_rate_dps))

    result = run(RobotSession(robot, SimClock(robot), "sim://", True, robot), CFG,
                 on_tick=on_tick)  # type: ignore[arg-type]
    assert result.outcome == "completed" and result.steps_climbed == 1
    pitches = [p for _, p, _ in seen]
    # it climbed: nose down, and up (by 0.1-0.4 deg as the run's timing
    # goes, far above the 1e-4 deg a robot at rest shows)
    assert min(pitches) < -2.0 and max(pitches) > 0.01
    # the sign agrees: where the pitch changes by more than a degree over
    # 0.2 s, the rates sampled meanwhile say the same way
    changes = 0
    for i in range(0, len(seen) - 10, 10):
        window = seen[i:i + 11]
        change = window[-1][1] - window[0][1]
        if abs(change) > 1.0:
            mean_rate = sum(r for _, _, r in window[:-1]) / 10
            assert mean_rate * change > 0, window
            changes += 1
    assert changes >= 2


def test_ideal_readings_are_never_old_and_are_shared() -> None:
    robot = SimRobot(CFG, ONE_STEP)
    for _ in range(5):
        snap = robot.read()
        for sid, reading in snap.sensors.items():
            assert reading.age_s == 0.0
            assert reading is robot.board.sensors[sid].reading(snap.time_s)  # not a copy
        robot.advance(TICK)


def test_a_timed_model_tells_each_reading_its_age() -> None:
    cfg = replace(CFG, sensors=msgspec.structs.replace(
        CFG.sensors, front_model="vl53l0x", back_model="hcsr04", front_fov_deg=None))
    robot = SimRobot(cfg, ONE_STEP)
    ages: dict[SensorId, set[float]] = {sid: set() for sid in SensorId}
    for _ in range(30):
        snap = robot.read()
        for sid, reading in snap.sensors.items():
            assert reading.age_s == pytest.approx(robot.board.sensors[sid].age(snap.time_s))
            ages[sid].add(round(reading.age_s, 6))
        robot.advance(TICK)
    # vl53l0x: a 30 ms period and 30 ms latency; hcsr04: 60 ms and 25 ms
    for sid, most in ((SensorId.SFR, 0.08), (SensorId.SBR, 0.1)):
        assert len(ages[sid]) > 2 and 0.0 < max(ages[sid]) <= most + 1e-9


def test_every_allowed_tilt_limit_stops_before_the_simulation_counts_a_fall() -> None:
    fields = {f.name: f.type for f in mi.type_info(Safety).fields}  # type: ignore[attr-defined]
    pitch = fields["max_pitch_deg"]
    most = (pitch.type if isinstance(pitch, mi.Metadata) else pitch).le  # (under its unit)
    assert CFG.safety.max_pitch_deg < most < WorldParams().pitch_limit_deg
