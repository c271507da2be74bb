"""Every shipped robot (`--config NAME`), each with its own sensor presets,
climbs the default stairs and comes home; and the config checks hold for
each (its back pair reads the floor it stands on, its "nothing ahead" is
within its front pair's range)."""

from __future__ import annotations

import pytest

from stairbot.config import load_config, shipped_configs
from stairbot.robots import RobotOptions, open_robot
from stairbot.runner import run
from stairbot.scenario import load_scenario


def test_every_sensor_preset_rides_on_a_shipped_robot() -> None:
    robots = [load_config(name) for name in shipped_configs()]
    used = {r.sensors.front_model for r in robots} | {r.sensors.back_model for r in robots}
    assert used == {"ideal", "vl53l1x", "vl53l0x", "hcsr04", "gp2y0a21"}


@pytest.mark.parametrize("name", shipped_configs())
def test_a_shipped_robot_climbs_the_default_stairs_and_comes_home(name: str) -> None:
    config = load_config(name)
    session = open_robot("sim://", config, RobotOptions(world=load_scenario()))
    try:
        r = run(session, config)
    finally:
        session.close()
    assert (r.outcome, r.ascent_end, r.steps_climbed, r.steps_descended) == (
        "completed", "top_reached", 5, 5), r.to_dict()
    assert not r.fell and r.pauses <= 1, r.to_dict()
    assert r.final_offset_m is not None and r.final_offset_m <= 0.05, r.to_dict()
