"""A robot config as the controller takes it: read from its file (or a
shipped robot by name), each field checked, and its values checked to fit
together against what the controller allows (the lowest riser it climbs
with this robot: :mod:`stairbot.control.algorithm.limits`)."""

from __future__ import annotations

from pathlib import Path

from stairbot.control.algorithm.limits import min_step_rise_m
from stairbot.inputs.config import RobotConfig, config_text, resolve_config
from stairbot.inputs.config_checks import check_consistency


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
