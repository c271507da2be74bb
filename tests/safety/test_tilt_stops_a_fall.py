"""A lift commanded past stability on the pymunk robot: the tilt supervisor
stops it before the physics calls it a fall, and the phase logic's own
stability check refuses it before it tilts at all.

The robot is the reference one with a heavy front segment (2.5 kg instead of
0.55: its centre of mass stands 12.9 mm ahead of segment 2's front axle) and
a 4 cm calibration lift.  Calibration lifts segments 1 and 3 off the floor
to turn on segment 2's wheels, and the robot tips onto its nose: the more
the lift rises, the more it pitches, until the simulation counts a fall at
35 degrees.  Three runs on the default stairs, each switch flipped
explicitly: the controller's ``check_stability`` and the config's
``[safety] imu``.
"""

from __future__ import annotations

from dataclasses import replace

import msgspec
import pytest

from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.texts.shared import UNSTABLE
from stairbot.control.robot_config import load_config
from stairbot.hardware import ZERO_SPEEDS, HasTruth, MotorId
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import load_scenario
from stairbot.run.robots import RobotOptions, RobotSession, open_robot
from stairbot.run.runner import RunResult, run

HOLD_S = 3.0
"""After the run, the robot is left standing this long with every motor at 0."""


def front_heavy(imu: bool) -> RobotConfig:
    cfg = load_config()
    return replace(cfg, masses=msgspec.structs.replace(cfg.masses, first_module=2.5),
                   algorithm=msgspec.structs.replace(cfg.algorithm, clearance_lift=0.04),
                   safety=msgspec.structs.replace(cfg.safety, imu=imu))


def run_front_heavy(imu: bool, check_stability: bool) -> tuple[RunResult, Controller,
                                                                RobotSession]:
    cfg = front_heavy(imu)
    session = open_robot("sim://", cfg, RobotOptions(world=load_scenario()))
    ctrl = Controller(cfg, check_stability=check_stability)
    return run(session, cfg, controller=ctrl, max_sim_time_s=60.0), ctrl, session


def lifts(session: RobotSession) -> tuple[float, float]:
    snap = session.robot.read()
    return snap.turns(MotorId.MTF), snap.turns(MotorId.MTB)


def test_unwatched_and_unchecked_the_lift_topples_the_robot() -> None:
    """The case is real: with neither the check nor the tilt watch, it falls."""
    result, _ctrl, session = run_front_heavy(imu=False, check_stability=False)
    assert isinstance(session.robot, HasTruth)
    assert result.fell and session.robot.truth().fell
    assert "pitched 35 deg" in str(result.error)
    assert not result.tilt_watched


def test_the_tilt_supervisor_stops_the_lift_before_the_fall() -> None:
    result, ctrl, session = run_front_heavy(imu=True, check_stability=False)
    robot = session.robot
    assert isinstance(robot, HasTruth)
    assert result.outcome == "error" and not result.fell and not robot.truth().fell
    assert ctrl.phase is Phase.ERROR
    error = str(result.error)
    assert error.startswith("tilt: segment 2's pitch is -15.") and "nose down" in error
    assert "beyond the limit ±15°: every motor stopped, lifts holding" in error
    truth = robot.truth()
    assert truth.max_pitch_deg is not None and 15.0 < truth.max_pitch_deg < 17.0
    # stopped, it stands: the lifts hold where they stopped and it does not tip on
    held = lifts(session)
    assert 0.0 < held[0] < load_config().NUMBER_OF_VERTICAL_TURNS_FOR_CLEARANCE * 4
    for _ in range(round(HOLD_S / 0.02)):
        robot.command(ZERO_SPEEDS)
        session.clock.advance(0.02)
    assert not robot.truth().fell
    assert lifts(session) == pytest.approx(held, abs=0.05)
    pitch = robot.truth().pitch_deg
    assert pitch is not None and abs(pitch) < 17.0


def test_the_stability_check_refuses_the_lift_before_any_tilt() -> None:
    result, ctrl, session = run_front_heavy(imu=True, check_stability=True)
    robot = session.robot
    assert isinstance(robot, HasTruth)
    assert result.outcome == "error" and not result.fell
    assert str(result.error).startswith(f"{UNSTABLE}: calibration — lift segments 1 and 3")
    truth = robot.truth()
    assert truth.max_pitch_deg is not None and truth.max_pitch_deg < 0.5
    assert lifts(session) == pytest.approx((0.0, 0.0), abs=0.05)  # nothing lifted
