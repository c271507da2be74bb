"""Simulated runs for the tests: a robot config on a scenario, through
``sim://``, the session closed whatever happens."""

from __future__ import annotations

from stairbot.control.algorithm.phases import Mode
from stairbot.events import Event, discard
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import RunResult, TickTap, run


def run_sim(config: RobotConfig, scenario: Scenario,
            events: list[Event] | None = None, *, limp_home: bool = False,
            tap: TickTap | None = None) -> RunResult:
    """``config``'s robot, simulated, on ``scenario`` (down from the top if it
    starts there); its events go to ``events`` if given; ``limp_home``: the
    operator consents to limp home (``stairbot run --yes``); ``tap`` sees
    every tick's snapshot and the speeds sent."""
    session = open_robot("sim://", config, RobotOptions(world=scenario))
    try:
        return run(session, config, discard if events is None else events.append,
                   Mode.for_start(scenario.start.on), limp_home=limp_home, tap=tap)
    finally:
        session.close()
