"""Tests for real boards: ``STAIRBOT_HW_URL=serial:///dev/ttyUSB0 pytest -m
hardware tests/hardware`` (any robot URL: ``can://socketcan/can0`` ...;
``STAIRBOT_HW_CONFIG`` names the robot config, default the reference robot).
Without the variable every test here is skipped.  Nothing here moves the
robot: the tests command zero speeds, latch and clear the e-stop, and read.
tests/drivers/test_hardware_marker.py runs them against the fake boards in
real time, so they are known to work before they meet a board."""

from __future__ import annotations

import os
from collections.abc import Iterator

import pytest

from stairbot.control.robot_config import load_config
from stairbot.drivers.board_robot import BoardRobot
from stairbot.inputs.config import RobotConfig
from stairbot.run.robots import RobotSession, open_robot

URL_VARIABLE = "STAIRBOT_HW_URL"


@pytest.fixture(scope="session")
def hw_url() -> str:
    url = os.environ.get(URL_VARIABLE)
    if not url:
        pytest.skip(f"no boards: set {URL_VARIABLE}=URL to run (pytest -m hardware)")
    return url


@pytest.fixture(scope="session")
def hw_config() -> RobotConfig:
    return load_config(os.environ.get("STAIRBOT_HW_CONFIG") or None)


@pytest.fixture
def session(hw_url: str, hw_config: RobotConfig) -> Iterator[RobotSession]:
    s = open_robot(hw_url, hw_config)
    try:
        yield s
    finally:
        s.robot.stop_all()
        s.close()


@pytest.fixture
def boards(session: RobotSession) -> BoardRobot:
    if not isinstance(session.robot, BoardRobot):
        pytest.skip(f"{session.url} is not boards on a wire")
    return session.robot
