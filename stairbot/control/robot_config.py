"""A robot config as the controller takes it: read from its file (or a
shipped robot by name), each field checked, and its values checked to fit
together against what the controller allows (the lowest riser it climbs
with this robot: :mod:`stairbot.control.algorithm.limits`)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from stairbot.control.algorithm.limits import min_step_rise_m
from stairbot.errors import ConfigError
from stairbot.inputs.config import RobotConfig, config_text, resolve_config
from stairbot.inputs.config_checks import check_consistency
from stairbot.inputs.scenario import Scenario
from stairbot.text import printable


def parse_config(text: str, source: str) -> RobotConfig:
    """Parse and validate a config document (and the one it ``extends``).
    Raises ConfigError naming the file, the field and what it allows."""
    cfg = resolve_config(text, source)
    check_consistency(cfg, min_step_rise_m)
    return cfg


def load_config(path: str | Path | None = None) -> RobotConfig:
    """Load a config file, a shipped robot by name (a plain word that is no
    existing file), or the reference robot when ``path`` is None.  Raises
    ConfigError."""
    return parse_config(*config_text(path))


def config_for(config: str | None, scenario: Scenario) -> tuple[RobotConfig, str | None]:
    """The robot config a run of ``scenario`` uses: ``config`` (``--config``)
    when given, else the robot the scenario names (``robot``), else the
    reference robot.  Also a one-line note when ``config`` overrides a
    scenario's robot that is another robot (its ``[expect]`` may not hold),
    else None.  Raises ConfigError."""
    if config is None:
        return load_config(scenario.robot), None
    chosen = load_config(config)
    if scenario.robot is None:
        return chosen, None
    try:
        own: RobotConfig | None = load_config(scenario.robot)
    except ConfigError:
        own = None
    if own is not None and replace(own, source=chosen.source) == chosen:
        return chosen, None
    return chosen, printable(f"note: --config {config} overrides the robot {scenario.name} "
                             f"is written for ({scenario.robot}): its [expect] may not hold")
