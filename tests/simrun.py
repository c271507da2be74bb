"""Simulated runs for the tests: a robot config on a scenario, through
``sim://``, the session closed whatever happens."""

from __future__ import annotations

from stairbot.control.algorithm.phases import Mode
from stairbot.events import Event, discard
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import RunResult, run


def run_sim(config: RobotConfig, scenario: Scenario,
            events: list[Event] | None = None) -> RunResult:
    """``config``'s robot, simulated, on ``scenario`` (down from the top if it
    starts there); its events go to ``events`` if given."""
    session = open_robot("sim://", config, RobotOptions(world=scenario))
    try:
        return run(session, config, discard if events is None else events.append,
                   Mode.for_start(scenario.start.on))
    finally:
        session.close()
