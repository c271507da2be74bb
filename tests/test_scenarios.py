"""Whole runs on the simulated robot: every shipped scenario ends as its
[expect] says, and the default stairs are climbed and descended back to the
start at several yaw offsets and noise seeds."""

from __future__ import annotations

import pytest

from stairbot.config import load_config
from stairbot.robots import RobotOptions, open_robot
from stairbot.runner import RunResult, run
from stairbot.scenario import Scenario, expectation_mismatches, load_scenario, parse_scenario
from stairbot.scenario import shipped_scenarios as shipped

CONFIG = load_config()


def run_sim(scenario: Scenario) -> RunResult:
    session = open_robot("sim://", CONFIG, scenario, RobotOptions())
    try:
        return run(session, CONFIG)
    finally:
        session.close()


@pytest.mark.parametrize("name", shipped())
def test_every_shipped_scenario_ends_as_it_expects(name: str) -> None:
    scenario = load_scenario(name)
    result = run_sim(scenario)
    assert expectation_mismatches(scenario.expect, result.to_dict()) == [], result.to_dict()


DEFAULT_AT = """
[stairs]
count = 5
rise = 0.17
tread = 0.28
[start]
distance = 0.5
yaw_deg = {yaw}
[sensors]
noise = 0.001
seed = {seed}
"""


@pytest.mark.parametrize("seed", [2, 7, 13])
@pytest.mark.parametrize("yaw", [15.0, -15.0, 8.0, -8.0])
def test_default_stairs_up_and_back_at_a_yaw_and_seed(yaw: float, seed: int) -> None:
    scenario = parse_scenario(DEFAULT_AT.format(yaw=yaw, seed=seed), f"yaw{yaw}_seed{seed}")
    r = run_sim(scenario)
    assert (r.outcome, r.ascent_end, r.steps_climbed, r.steps_descended) == (
        "completed", "top_reached", 5, 5), r.to_dict()
    assert not r.fell
    assert r.final_offset_m is not None and r.final_offset_m <= 0.05, r.to_dict()

