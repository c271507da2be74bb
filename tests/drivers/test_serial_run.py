"""The whole ascent and descent over the wire: `stairbot fake-boards --serial
--lockstep` in another process, the runner in this one on serial://<pty>,
ending exactly as sim:// does."""

from __future__ import annotations

import signal
from collections.abc import Iterator
from pathlib import Path

import pytest
from lockstep_boards import lockstep_boards
from lost_sensor import TWO_STEPS

from stairbot.control.robot_config import load_config
from stairbot.inputs.scenario import load_scenario
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import RunResult, run

SAME = ("outcome", "ascent_end", "steps_climbed", "steps_descended", "pauses", "fell")


@pytest.fixture
def fake_boards_url(tmp_path: Path) -> Iterator[str]:
    with lockstep_boards(tmp_path, stop=signal.SIGTERM) as boards:
        yield boards.url
    assert boards.returncode == 0, boards.stderr
    assert "frames in" in boards.stderr  # the fake reports its own counters on SIGTERM


def test_full_ascent_and_descent_over_a_pty_ends_as_sim_does(fake_boards_url: str) -> None:
    config, scenario = load_config(), load_scenario()
    sim = run(open_robot("sim://", config, RobotOptions(world=scenario)), config)
    session = open_robot(fake_boards_url + "&timeout=2", config)
    try:
        wire: RunResult = run(session, config)
        health = session.robot.diagnostics()["link"]
    finally:
        session.close()
    assert sim.outcome == "completed" and sim.steps_climbed == 5
    assert {k: getattr(wire, k) for k in SAME} == {k: getattr(sim, k) for k in SAME}
    assert wire.sim_time_s == pytest.approx(sim.sim_time_s, abs=1.0)
    assert wire.final_offset_m is not None and wire.final_offset_m < 0.05
    assert isinstance(health, dict) and health["lost"] == 0 and health["crc_errors"] == 0


STUCK = TWO_STEPS + """[[faults]]
at = 42.0
sensor = "SFR"
kind = "stuck"
"""


def test_a_stuck_sensor_reads_stuck_over_the_wire_and_the_run_ends_as_sim_does(
        tmp_path: Path) -> None:
    # the fake boards publish the simulation's sensor model: a stuck SFR sends
    # fresh frames of one value, which the host judges stuck as on sim://
    path = tmp_path / "stuck.toml"
    path.write_text(STUCK)
    config, scenario = load_config(), load_scenario(path)
    sim = run(open_robot("sim://", config, RobotOptions(world=scenario)), config,
              limp_home=True)
    with lockstep_boards(tmp_path, stop=signal.SIGTERM, scenario=str(path)) as boards:
        session = open_robot(boards.url + "&timeout=2", config)
        try:
            wire: RunResult = run(session, config, limp_home=True)
        finally:
            session.close()
    assert sim.outcome == "came_home_degraded" and sim.ascent_end == "sensor_lost"
    assert {k: getattr(wire, k) for k in SAME} == {k: getattr(sim, k) for k in SAME}
    assert wire.final_offset_m is not None and wire.final_offset_m < 0.05
