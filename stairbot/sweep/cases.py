"""Cases: a case index becomes a scenario TOML (and a robot config TOML when
the spec overrides the robot), built and validated by the same loaders that
``stairbot run --scenario/--config`` use, so what a sweep runs is what a person
reproduces from the files it writes.

:func:`check_spec` builds every case (or the first ``limit``) before any
runs, one at a time: a value the loaders refuse (and the edges of every
distribution) stops the sweep with a SpecError naming the axis.  How many
cases a spec makes is counted from its axes (:attr:`Spec.total`), without
building any.  A case's facts carry its zone (:mod:`stairbot.sweep.zones`).
"""

from __future__ import annotations

import copy
import math
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass, field
from functools import cache
from importlib import resources
from typing import Any

from stairbot.control.algorithm import limits
from stairbot.control.robot_config import parse_config
from stairbot.errors import ConfigError, ScenarioError
from stairbot.inputs.config import DEFAULT_CONFIG_NAME, RobotConfig
from stairbot.inputs.scenario import (
    DEFAULT_COUNT,
    DEFAULT_RISE,
    DEFAULT_TREAD,
    parse_scenario,
)
from stairbot.inputs.schema import _tokens
from stairbot.sweep import tomlw
from stairbot.sweep.axes import VIRTUAL, Axis, SpecError, case_rng
from stairbot.sweep.spec import Spec
from stairbot.sweep.zones import zone

DIGITS = 6  # drawn values are rounded to a micrometre (or a micro-degree) before use


@dataclass(frozen=True)
class Case:
    """One case, ready to run: its index, its axis values, the documents, and
    the facts the verdict needs (limits, zone, steps expected)."""

    index: int
    axes: dict[str, Any]
    scenario_text: str
    config_text: str | None  # None: the reference robot
    facts: dict[str, Any] = field(default_factory=dict)


@cache
def _default_config_text() -> str:
    return resources.files("stairbot.inputs").joinpath(DEFAULT_CONFIG_NAME).read_text("utf-8")


@cache
def _parsed_config(text: str | None) -> RobotConfig:
    return parse_config(text or _default_config_text(), "<config>")


def _set(doc: dict[str, Any], path: str, value: Any) -> None:
    tokens = _tokens("." + path)
    node: Any = doc
    for tok, nxt in zip(tokens, tokens[1:], strict=False):
        if isinstance(tok, int):
            if not isinstance(node, list) or tok >= len(node):
                have = len(node) if isinstance(node, list) else 0
                raise IndexError(f"the base has {have} such entries")
            node = node[tok]
        else:
            node = node.setdefault(tok, [] if isinstance(nxt, int) else {})
    last = tokens[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or last >= len(node):
            raise IndexError(f"the base has {len(node) if isinstance(node, list) else 0} entries")
        node[last] = value
    else:
        node[last] = value


def _round(value: Any) -> Any:
    return round(value, DIGITS) if isinstance(value, float) else value


def _jitter(spec: Spec, index: int, stairs: dict[str, Any], values: dict[str, Any]) -> None:
    """Per-step variation: replace count/rise/tread by explicit steps, each step's
    rise and tread moved by a uniform draw of at most the jitter."""
    rj = float(values.get("stairs.rise_jitter", 0.0) or 0.0)
    tj = float(values.get("stairs.tread_jitter", 0.0) or 0.0)
    if rj == 0.0 and tj == 0.0:
        return
    if "steps" in stairs:
        steps = [dict(s) for s in stairs.pop("steps")]
    else:
        count = stairs.pop("count", DEFAULT_COUNT)
        rise, tread = stairs.pop("rise", DEFAULT_RISE), stairs.pop("tread", DEFAULT_TREAD)
        steps = [{"rise": rise, "tread": tread} for _ in range(count)]
    rng = case_rng(spec.seed, index, "stairs.jitter")
    for s in steps:
        s["rise"] = round(float(s["rise"]) + rng.uniform(-rj, rj), DIGITS)
        s["tread"] = round(float(s["tread"]) + rng.uniform(-tj, tj), DIGITS)
    stairs.pop("count", None)
    stairs.pop("rise", None)
    stairs.pop("tread", None)
    stairs["steps"] = steps


def build_case(spec: Spec, index: int, override: tuple[str, Any] | None = None,
               chosen: dict[str, Any] | None = None) -> Case:
    """Case ``index`` (with one axis forced to a value, to check a distribution's
    edges; or with every axis's value ``chosen``, as a search chooses them).
    Raises SpecError when the loaders refuse what the axes make."""
    axes = spec.axis_values(index) if chosen is None else chosen
    values = {p: _round(v) for p, v in axes.items()}
    if override is not None:
        values[override[0]] = _round(override[1])
    scen = copy.deepcopy(_base(spec.scenario_text))
    scen.pop("expect", None)
    has_config = spec.config_text is not None or any(p.startswith("config.") for p in values)
    cfg = copy.deepcopy(_base(spec.config_text or _default_config_text())) if has_config else None
    for path, value in values.items():
        if path in VIRTUAL:
            continue
        target, sub = (cfg, path.removeprefix("config.")) if path.startswith("config.") else (
            scen, path)
        assert target is not None
        if path in ("stairs.count", "stairs.rise", "stairs.tread"):
            scen.setdefault("stairs", {}).pop("steps", None)
        if path == "stairs.steps":
            for k in ("count", "rise", "tread"):
                scen.setdefault("stairs", {}).pop(k, None)
        try:
            # a copy: a later axis may set a field inside it (faults, then faults[0].at)
            _set(target, sub, copy.deepcopy(value))
        except IndexError as exc:
            raise SpecError(spec.source, f"axes.{path}", str(exc)) from None
    _jitter(spec, index, scen.setdefault("stairs", {}), values)
    scen["name"] = f"{spec.name}-{index:06d}"
    scen["description"] = f"case {index} of sweep {spec.name} ({spec.hash[:12]})"
    scenario_text = tomlw.dumps(scen)
    config_text = None if cfg is None else tomlw.dumps(cfg)
    where = f"case {index}" + (f" ({override[0]} = {override[1]!r})" if override else "")
    try:
        scenario = parse_scenario(scenario_text, "<case>")
    except ScenarioError as exc:
        raise _blame(spec, exc.field, "", exc.problem, where, values) from None
    try:
        config = _parsed_config(config_text)
    except ConfigError as exc:
        raise _blame(spec, exc.field, "config.", exc.problem, where, values) from None
    z, max_rise, min_tread = zone(scenario, config, spec.rules)
    facts = {
        "zone": z, "count": len(scenario.steps), "max_rise_m": max_rise,
        "min_tread_m": min_tread if math.isfinite(min_tread) else None,
        "limit_rise_m": round(limits.max_step_rise_m(config), DIGITS),
        "limit_tread_m": round(limits.min_tread_m(config), DIGITS),
        "expected_steps": min(len(scenario.steps), config.algorithm.max_steps),
        "faults": len(scenario.faults), "home_m": spec.rules.home_m,
    }
    if scenario.start.on == "top":
        facts["from_top"] = True
        facts["expected_steps"] = len(scenario.steps)
    if scenario.landing is not None:
        # all of both flights: the landing's zone says whether it turns
        facts["expected_steps"] = min(len(scenario.steps) + len(scenario.landing.steps),
                                      config.algorithm.max_steps)
        facts["landing_turn"] = scenario.landing.turn
    return Case(index, values, scenario_text, config_text, facts)


@cache
def _base_cached(text: str) -> dict[str, Any]:
    return tomllib.loads(text)


def _base(text: str) -> dict[str, Any]:
    return _base_cached(text)


def _blame(spec: Spec, field_: str | None, prefix: str, problem: str, where: str,
           values: dict[str, Any]) -> SpecError:
    """Name the axis that made the loaders refuse a case (or the base file)."""
    full = f"{prefix}{field_}" if field_ else None
    axis = next((p for p in values if full is not None and (
        p == full or full.startswith(p + ".") or full.startswith(p + "["))), None)
    if axis is None and full is not None and full.startswith("stairs.steps"):
        axis = next((p for p in values if p.startswith("stairs.")), None)
    if axis is None:
        axis = next((p for p in values if p.startswith(prefix or "@")), None) if prefix else None
    name = f"axes.{axis}" if axis else ("sweep.config" if prefix else "sweep.scenario")
    what = "robot config" if prefix else "scenario"
    return SpecError(spec.source, name, f"{where}: the {what} refuses it: "
                     f"{full or 'the document'}: {problem}")


def iter_cases(spec: Spec, limit: int | None = None) -> Iterator[Case]:
    """The spec's cases in index order, the first ``limit`` of them (all when
    None), each built and validated only when asked for; the edges of each
    distribution are checked before the first.  Raises SpecError at the first
    case the loaders refuse."""
    if spec.total == 0:
        raise SpecError(spec.source, "axes", "the axes give no cases")
    for axis in spec.axes:
        if axis.sampled:
            _check_edges(spec, axis)
    for index in range(spec.total if limit is None else min(limit, spec.total)):
        yield build_case(spec, index)


def check_spec(spec: Spec, limit: int | None = None) -> list[Case]:
    """The spec's first ``limit`` cases (every case when None), built and
    validated, after the edges of each distribution are checked.  Raises
    SpecError (nothing has run)."""
    return list(iter_cases(spec, limit))


def _check_edges(spec: Spec, axis: Axis) -> None:
    for value in axis.extremes():
        build_case(spec, 0, (axis.path, value))
