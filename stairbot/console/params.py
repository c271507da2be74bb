"""What the parameters screen (``i``) shows: the resolved robot config, each
value with its unit (the schema's, :func:`stairbot.inputs.schema.unit_at`)
and the config of the ``extends`` chain that set it, and the limits the
controller works from, each worked out by the controller's own function on
the config (never a copy of its formula).  Pure: no Textual here."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import msgspec

from stairbot.control import tolerances
from stairbot.control.algorithm import edge_measure, guards, limits, touchdown
from stairbot.errors import StairbotError
from stairbot.inputs.config import (
    RobotConfig,
    config_text,
    resolve_config,
    robot_shown,
    source_ref,
    value_sources,
)
from stairbot.inputs.schema import unit_at
from stairbot.inputs.sections import ConfigFile

SECTIONS = ("geometry", "masses", "motors", "sensors", "algorithm", "safety")
DEFAULT = "the schema's default"
"""Where a value no config of the chain sets comes from."""


@dataclass(frozen=True)
class Value:
    """One value of the resolved config."""

    key: str
    """``section.name``, as the TOML file spells it."""
    value: Any
    unit: str | None
    source: str | None
    """The config that set it (as a person reads it: a path, ``reference
    (shipped)``), :data:`DEFAULT`, or None when it cannot be told."""


def values(cfg: RobotConfig) -> tuple[list[Value], str]:
    """Every value of ``cfg``, section by section, and a note ("" when none):
    why where they came from is not shown (the file changed or went since it
    was loaded)."""
    sources, note = _sources(cfg)
    out: list[Value] = []
    for section in SECTIONS:
        table = msgspec.to_builtins(getattr(cfg, section))
        for name, value in table.items():
            key = f"{section}.{name}"
            source = None if sources is None else sources.get(key, DEFAULT)
            out.append(Value(key, value, unit_at(ConfigFile, key), source))
    return out, note


def _sources(cfg: RobotConfig) -> tuple[dict[str, str] | None, str]:
    """Which config set each value, read again from the chain's files; None
    (and why) when they no longer resolve to ``cfg``."""
    try:
        text, source = config_text(source_ref(cfg.source))
        if resolve_config(text, source) != cfg:
            return None, (f"{robot_shown(cfg.source)} changed since it was loaded: "
                          "where each value came from is not shown")
        return {k: robot_shown(v) for k, v in value_sources(text, source).items()}, ""
    except (StairbotError, OSError) as exc:
        return None, f"where each value came from is not shown: {exc}"


@dataclass(frozen=True)
class Limit:
    """A figure the controller works from, worked out from the config."""

    group: str
    name: str
    value: float | int | str
    unit: str | None
    by: str
    """The function that works it out (module.name), for the operator who
    wants to read why."""


def _unit_of(name: str) -> str | None:
    """A :func:`~stairbot.control.algorithm.limits.derived` figure's unit, by
    the house's naming (``_m``, ``_m_s``, turn counts)."""
    if name.endswith("_m_s"):
        return "m/s"
    if name.endswith("_m") or name in ("LENGTH_OF_A_ROBOT", "BACK_CLEARANCE"):
        return "m"
    if "TURNS" in name or name == "number_of_vertical_turns":
        return "turns"
    return None


Figure = Callable[[RobotConfig], float | int]

TIMING: tuple[tuple[str, str, Figure, str], ...] = (
    ("phase_timeout_s", "guards.phase_timeout_s", guards.phase_timeout_s, "s"),
    ("front_max_age_s", "tolerances.max_age (front)",
     lambda c: tolerances.max_age(c, False), "s"),
    ("back_max_age_s", "tolerances.max_age (back)", lambda c: tolerances.max_age(c, True), "s"),
    ("front_settle_s", "tolerances.settle_s (front)",
     lambda c: tolerances.settle_s(c, False), "s"),
    ("back_settle_s", "tolerances.settle_s (back)", lambda c: tolerances.settle_s(c, True), "s"),
    ("edge_lag_s", "edge_measure.edge_lag_s", edge_measure.edge_lag_s, "s"),
    ("touchdown_smoothing_ticks", "touchdown.smoothing_ticks", touchdown.smoothing_ticks,
     "ticks"),
)
"""Timeouts and timings: how long the controller waits, and for what."""

TOLERANCES: tuple[tuple[str, str, Figure, str], ...] = (
    ("floor_tolerance_m", "edge_measure.floor_tolerance", edge_measure.floor_tolerance, "m"),
    ("edge_clearance_m", "edge_measure.edge_clearance_m", edge_measure.edge_clearance_m, "m"),
    ("edge_drop_m", "edge_measure.edge_drop_m", edge_measure.edge_drop_m, "m"),
    ("touchdown_margin_m", "touchdown.margin_m", touchdown.margin_m, "m"),
    ("touchdown_pitch_deg", "touchdown.pitch_deg", touchdown.pitch_deg, "°"),
)
"""Tolerances and margins: how near is near enough."""


def derived_limits(cfg: RobotConfig) -> list[Limit]:
    """The figures the controller works from, each by its own function:
    what it climbs (:func:`~stairbot.control.algorithm.limits.derived`, as
    ``stairbot config show`` prints them), its timings, its tolerances."""
    out = [Limit("what it climbs and how fast", name, value, _unit_of(name),
                 "limits.derived") for name, value in limits.derived(cfg).items()]
    refusal = limits.narrow_steps_refusal(cfg) if cfg.algorithm.narrow_steps else None
    if refusal is not None:
        out.append(Limit("what it climbs and how fast", "narrow_steps_refused", refusal, None,
                         "limits.narrow_steps_refusal"))
    for group, figures in (("timeouts and timings", TIMING),
                           ("tolerances and margins", TOLERANCES)):
        out += [Limit(group, name, fn(cfg), unit, by) for name, by, fn, unit in figures]
    return out


def shown_value(value: Any) -> str:
    """A value as the TOML file spells it (a number to 6 significant
    figures); a key left out (None) as ``(left out)``."""
    if value is None:
        return "(left out)"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "inf" if math.isinf(value) else f"{value:.6g}"
    if isinstance(value, str):
        return f'"{value}"'
    return str(value)
