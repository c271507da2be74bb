"""The tilt watch: the supervisor stops the robot on a pitch, a roll or a rate
beyond [safety]'s limits, on a declared IMU that is missing or not a number,
and says so; a stale IMU reading holds the robot (every motor stopped) until
a fresh one comes, for at most the sensor wait; a robot declared without an
IMU is never said to be watched."""

from __future__ import annotations

import math
from dataclasses import replace

import msgspec
import pytest
from kinematic import KinematicRobot, run

from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.phases import Phase
from stairbot.control.robot_config import load_config
from stairbot.control.tilt import TiltWatch
from stairbot.events import Event, EventKind
from stairbot.hardware import Imu, MotorId, MotorState, SensorId, SensorReading, Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import load_scenario
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import run as run_session

CFG = load_config("ideal")  # the algorithm's logic, on the readings it was written for
SAFETY = CFG.safety
TICK = CFG.algorithm.tick


def without_imu(cfg: RobotConfig = CFG) -> RobotConfig:
    return replace(cfg, safety=msgspec.structs.replace(cfg.safety, imu=False))


def snap(imu: Imu | None) -> Snapshot:
    sensors = {s: SensorReading(0.5) for s in SensorId}
    return Snapshot(1.0, sensors, {m: MotorState(0.0) for m in MotorId}, imu=imu)


# -- the watch alone, on made-up snapshots ----------------------------------------------
def test_the_reference_robot_watches_tilt_well_inside_the_fall_limit() -> None:
    assert SAFETY.imu and 3.7 < SAFETY.max_pitch_deg < 35.0  # see default_robot.toml
    assert TiltWatch(SAFETY).check(snap(Imu(3.7, 0.0, 45.0, 0.0))) is None  # a normal climb


@pytest.mark.parametrize(("imu", "words"), [
    (Imu(15.5, 0.0), ("pitch is +15.5°", "nose up", "±15°")),
    (Imu(-16.0, 0.0), ("pitch is -16.0°", "nose down", "±15°")),
    (Imu(0.0, 15.2), ("roll is +15.2°", "right side down", "±15°")),
    (Imu(0.0, -30.0), ("roll is -30.0°", "left side down")),
    (Imu(2.0, 0.0, pitch_rate_dps=-130.0), ("pitch rate is -130.0°/s", "±120°/s")),
    (Imu(0.0, 0.0, roll_rate_dps=121.0), ("roll rate is +121.0°/s",)),
])
def test_beyond_a_limit_is_a_reason_to_stop_naming_value_and_limit(
        imu: Imu, words: tuple[str, ...]) -> None:
    reason = TiltWatch(SAFETY).check(snap(imu))
    assert reason is not None and reason.startswith("tilt: ")
    assert "every motor stopped, lifts holding" in reason
    for w in words:
        assert w in reason


def test_at_the_limit_is_not_beyond_it() -> None:
    s = SAFETY
    at = Imu(-s.max_pitch_deg, s.max_roll_deg, s.max_rate_dps, -s.max_rate_dps,
             age_s=s.imu_max_age_s)
    assert TiltWatch(s).check(snap(at)) is None


@pytest.mark.parametrize(("imu", "words"), [
    (None, "IMU missing"),
    (Imu(math.nan, 0.0), "IMU error"),
    (Imu(0.0, 0.0, roll_rate_dps=math.inf), "IMU error"),
    (Imu(0.0, 0.0, age_s=math.inf), "IMU error"),
])
def test_a_declared_imu_missing_stale_or_broken_stops_the_robot(imu: Imu | None,
                                                                 words: str) -> None:
    reason = TiltWatch(SAFETY).check(snap(imu))
    assert reason is not None and words in reason and "stopped" in reason


def test_a_stale_imu_reading_is_a_reason_to_hold_not_to_end() -> None:
    watch, s = TiltWatch(SAFETY), SAFETY
    old = snap(Imu(2.0, 0.0, age_s=0.35))
    assert watch.check(old) is None
    assert watch.stale(old) == ("IMU stale (tilt cannot be watched): its reading is 0.350 s "
                                "old (limit 0.1 s)")
    assert watch.stale(snap(Imu(2.0, 0.0, age_s=s.imu_max_age_s))) is None  # at the limit
    assert watch.stale(snap(None)) is None  # missing: check's, an end
    # beyond a limit, however old: the robot was there
    assert "pitch is +16.0°" in str(watch.check(snap(Imu(16.0, 0.0, age_s=0.35))))
    assert TiltWatch(without_imu().safety).stale(old) is None


def test_without_a_declared_imu_nothing_is_watched_and_it_says_so() -> None:
    watch = TiltWatch(without_imu().safety)
    assert not watch.watched
    assert watch.check(snap(None)) is None
    assert watch.check(snap(Imu(40.0, 0.0))) is None  # not watched: never claimed to be
    assert "tilt not watched" in watch.describe()
    assert "tilt watched" in TiltWatch(SAFETY).describe()


# -- in the controller: a stop with an error, lifts holding ------------------------------
def start(cfg: RobotConfig = CFG) -> tuple[Controller, KinematicRobot, list[Event]]:
    events: list[Event] = []
    return Controller(cfg, events.append), KinematicRobot(cfg, steps=[(0.17, 0.28)]), events


def assert_stopped_for_good(ctrl: Controller, robot: KinematicRobot) -> None:
    assert ctrl.finished and ctrl.result.outcome == "error"
    for _ in range(5):
        assert ctrl.tick(robot.read()) == dict.fromkeys(MotorId, 0.0)
        robot.advance(TICK)


@pytest.mark.parametrize("phase", [Phase.ASCENT_LIFT_FIRST, Phase.ASCENT_DRIVE_SECOND,
                                   Phase.DESCENT_LOWER_THIRD])
def test_a_tilt_mid_run_stops_every_motor_at_the_next_tick(phase: Phase) -> None:
    ctrl, robot, events = start()
    run(ctrl, robot, until=lambda c: c.phase is phase)
    assert any(v != 0.0 for v in ctrl.tick(robot.read()).values())  # it was moving
    robot.imu = Imu(-17.5, 0.0, -40.0)
    assert ctrl.tick(robot.read()) == dict.fromkeys(MotorId, 0.0)
    assert "tilt: segment 2's pitch is -17.5°" in str(ctrl.result.error)
    errors = [e for e in events if e.kind is EventKind.ERROR]
    assert errors and "±15°" in errors[-1].message
    assert_stopped_for_good(ctrl, robot)


def test_a_tilt_stop_on_a_link_that_lost_frames_in_the_phase_names_the_link() -> None:
    """Found by the real-time soak at 20 % (serial, frames dropped): a run
    ended on the tilt limit in descent and the error did not say that the
    wire had been losing frames all through the phase."""
    ctrl, robot, _ = start()
    read = robot.read
    figures = {"retries": 4.0, "lost": 1.0}

    def lossy() -> Snapshot:
        figures["retries"] += 2
        return replace(read(), health=dict(figures))

    robot.read = lossy  # type: ignore[method-assign]
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_DRIVE_SECOND)
    at_entry = figures["retries"]
    for _ in range(10):
        ctrl.tick(robot.read())
        robot.advance(TICK)
    robot.imu = Imu(-15.2, 0.0, -40.0)
    ctrl.tick(robot.read())
    error = str(ctrl.result.error)
    assert error.startswith("tilt: segment 2's pitch is -15.2°"), error
    grown = round(figures["retries"] - at_entry)
    assert error.endswith(f"; meanwhile the link lost frames ({grown} retries)"), error


def test_an_imu_that_stops_answering_stops_the_robot() -> None:
    ctrl, robot, _ = start()
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_APPROACH)
    robot.imu = None
    run(ctrl, robot)
    assert "IMU missing" in str(ctrl.result.error)
    assert_stopped_for_good(ctrl, robot)


def test_a_stale_imu_stops_every_motor_at_once_and_the_run_goes_on_when_it_is_fresh(
        ) -> None:
    ctrl, robot, events = start()
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_DRIVE_SECOND)
    assert any(v != 0.0 for v in ctrl.tick(robot.read()).values())  # it was moving
    fresh, robot.imu = robot.imu, Imu(0.0, 0.0, age_s=0.12)
    for _ in range(3):  # three ticks on a reading too old to watch tilt by
        assert ctrl.tick(robot.read()) == dict.fromkeys(MotorId, 0.0)
        robot.advance(TICK)
    assert not ctrl.finished and ctrl.phase is Phase.ASCENT_DRIVE_SECOND
    held = [e for e in events if e.kind is EventKind.PAUSE]
    assert len(held) == 1 and "IMU stale (tilt cannot be watched)" in held[0].message
    assert "all motors stopped, lifts holding" in held[0].message
    assert held[0].data["imu_stale"] is True
    robot.imu = fresh
    run(ctrl, robot)
    assert ctrl.result.outcome == "completed", ctrl.result.error
    assert ctrl.result.pauses >= 1
    assert any(e.kind is EventKind.RESUME and "sensors back" in e.message for e in events)


def test_an_imu_stale_for_longer_than_the_sensor_wait_ends_the_run() -> None:
    ctrl, robot, _ = start()
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_LIFT_FIRST)
    robot.imu = Imu(0.0, 0.0, age_s=0.5)
    sent = run(ctrl, robot, max_time=robot.t + 5.0)
    assert all(v == 0.0 for speeds in sent for v in speeds.values())
    assert ctrl.result.outcome == "error"
    assert "IMU stale (tilt cannot be watched)" in str(ctrl.result.error)
    assert "for 1 s in ascent" in str(ctrl.result.error)
    assert_stopped_for_good(ctrl, robot)


def test_a_robot_without_the_declared_imu_never_moves() -> None:
    ctrl, robot, events = start()
    robot.imu = None
    sent = run(ctrl, robot)
    assert all(v == 0.0 for speeds in sent for v in speeds.values())
    assert "IMU missing" in str(ctrl.result.error)
    said = [e.message for e in events if e.kind is EventKind.INFO]
    assert said[0].startswith("tilt watched")


def test_a_robot_declared_without_an_imu_runs_and_says_tilt_is_not_watched() -> None:
    cfg = without_imu()
    ctrl, robot, events = start(cfg)
    robot.imu = None
    run(ctrl, robot)
    assert ctrl.result.outcome == "completed"
    infos = [e for e in events if e.kind is EventKind.INFO]
    assert infos[0].message.startswith("tilt not watched")
    assert infos[0].data["tilt_watched"] is False


def test_the_run_summary_says_whether_tilt_was_watched() -> None:
    for cfg, watched in ((CFG, True), (without_imu(), False)):
        events: list[Event] = []
        session = open_robot("sim://", cfg, RobotOptions(
            world=load_scenario("calibration_case1_open_floor")))
        result = run_session(session, cfg, sink=events.append)
        assert result.tilt_watched is watched and result.to_dict()["tilt_watched"] is watched
        summary = [e for e in events if e.kind is EventKind.SUMMARY][0]
        assert ("tilt not watched" in summary.message) is not watched
