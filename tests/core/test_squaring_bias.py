"""Descent 1's squaring turn bounded by the heading the step was climbed with
(squaring_bias.py): a healthy pair still squares up to a riser the
odometer lost by less than the bound allows.  The ideal robot on the
kinematic stand-in, turned while descent 6 of step 2 lowers segment 1 (a
turn the odometer does not see, as a slip would be; standing, the bias
watch would take the jump of the pair's readings for an onset)."""

from __future__ import annotations

import math

import pytest
from kinematic import KinematicRobot, run

from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.squaring_bias import allowed_rad
from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind

CFG = load_config("ideal")


@pytest.mark.parametrize("deg", [6.0, 9.0])
def test_a_healthy_pair_squares_up_to_a_heading_the_odometer_lost_within_the_bound(
        deg: float) -> None:
    assert deg < math.degrees(allowed_rad(CFG, 0.1))  # 10.6 deg on the ideal robot
    events: list[Event] = []
    ctrl = Controller(CFG, events.append)
    robot = KinematicRobot(CFG, steps=[(0.17, 0.28)] * 2)
    run(ctrl, robot, until=lambda c: c.phase is Phase.DESCENT_LOWER_FIRST)
    robot.yaw += math.radians(deg)
    run(ctrl, robot)
    assert ctrl.result.outcome == "completed", ctrl.result
    infos = [e.message for e in events if e.kind is EventKind.INFO]
    assert [m for m in infos if m.startswith("calibration (descent 1, step 1)")
            and "case 2" in m], infos  # it squared up on step 1
    assert not [m for m in infos if "chases an offset" in m], infos
