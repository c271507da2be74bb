"""The sweep spec: which axes to vary, how, and the verdict rules.

A spec is a TOML file (docs/envelope.md)::

    [sweep]
    name = "limits"          # default: the file name
    seed = 7                 # master seed of every sampled axis
    cases = 4                # samples per grid point (with sampled axes)
    scenario = "default"     # base scenario: a file (relative to the spec) or a shipped name
    config = "robot.toml"    # base robot config (default: the robot the base scenario
                             # names, else the reference robot)

    [axes]                   # dotted paths into the scenario, or config.SECTION.KEY
    "stairs.rise" = { range = [0.18, 0.22, 0.005] }   # grid: start, stop, step
    "stairs.tread" = [0.26, 0.28]                     # grid: these values
    "start.yaw_deg" = { uniform = [-20, 20] }         # sampled per case
    "sensors.seed" = { randint = [1, 1000000] }

    [verdict]                # all optional
    rise_margin_m = 0.01
    tread_margin_m = 0.01
    home_m = 0.05

    [report]
    x = "stairs.tread"
    y = "stairs.rise"

A spec makes at most :data:`MAX_CASES` cases, counted from its axes.
Everything wrong with a spec raises :class:`SpecError` (exit 2, one line).
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Annotated, Any

import msgspec

from stairbot.errors import ConfigError
from stairbot.inputs.config import config_table
from stairbot.inputs.schema import convert, load_toml, read_text
from stairbot.sweep import tomlw
from stairbot.sweep.axes import (
    MAX_CASES,
    Axis,
    SpecError,
    case_rng,
    flatten,
    parse_axis,
)
from stairbot.text import check_line, printable


class SweepTable(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    name: str | None = None
    description: str = ""
    seed: int = 1
    cases: Annotated[int, msgspec.Meta(ge=1, le=1_000_000)] = 1
    scenario: str | None = None
    config: str | None = None


class VerdictTable(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    rise_margin_m: Annotated[float, msgspec.Meta(ge=0)] = 0.01
    tread_margin_m: Annotated[float, msgspec.Meta(ge=0)] = 0.01
    home_m: Annotated[float, msgspec.Meta(gt=0)] = 0.05


class ReportTable(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    x: str | None = None
    y: str | None = None
    worst: Annotated[int, msgspec.Meta(ge=0)] = 10
    bins: Annotated[int, msgspec.Meta(ge=2, le=40)] = 12


class SpecFile(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    sweep: SweepTable = msgspec.field(default_factory=SweepTable)
    axes: dict[str, Any] = msgspec.field(default_factory=dict)
    verdict: VerdictTable = msgspec.field(default_factory=VerdictTable)
    report: ReportTable = msgspec.field(default_factory=ReportTable)


@dataclass(frozen=True)
class Rules:
    rise_margin_m: float = 0.01
    tread_margin_m: float = 0.01
    home_m: float = 0.05


@dataclass(frozen=True)
class Spec:
    source: str
    name: str
    description: str
    seed: int
    samples: int
    axes: tuple[Axis, ...]
    rules: Rules
    scenario_text: str
    config_text: str | None
    report: ReportTable
    raw: dict[str, Any] = field(repr=False)

    @property
    def hash(self) -> str:
        blob = json.dumps({"spec": self.raw, "scenario": self.scenario_text,
                           "config": self.config_text}, sort_keys=True)
        return hashlib.sha256(blob.encode()).hexdigest()

    @property
    def grid_axes(self) -> tuple[Axis, ...]:
        return tuple(a for a in self.axes if not a.sampled)

    @property
    def sampled_axes(self) -> tuple[Axis, ...]:
        return tuple(a for a in self.axes if a.sampled)

    @property
    def grid_size(self) -> int:
        return math.prod(len(a.values) for a in self.grid_axes)

    @property
    def samples_per_point(self) -> int:
        return self.samples if self.sampled_axes else 1

    @property
    def total(self) -> int:
        return self.grid_size * self.samples_per_point

    def axis_values(self, index: int) -> dict[str, Any]:
        """Every axis's value in case ``index``: the grid point is index //
        samples (axes in spec order, the last varying fastest), each sampled
        axis is drawn from its own generator seeded by (seed, index, path)."""
        if not 0 <= index < self.total:
            raise IndexError(f"case {index} is outside 0..{self.total - 1}")
        point, _ = divmod(index, self.samples_per_point)
        out: dict[str, Any] = {}
        grid = self.grid_axes
        sizes = [len(a.values) for a in grid]
        for axis, size in zip(reversed(grid), reversed(sizes), strict=True):
            point, k = divmod(point, size)
            out[axis.path] = axis.values[k]
        for axis in self.sampled_axes:
            out[axis.path] = axis.draw(case_rng(self.seed, index, axis.path))
        return {a.path: out[a.path] for a in self.axes}


def _base_text(spec_dir: Path, name: str | None, src: str, key: str, default: str,
               folder: str | None) -> str:
    if name is None:
        return resources.files("stairbot.inputs").joinpath(default).read_text("utf-8")
    p = spec_dir / name
    if p.is_file():
        return read_text(p, SpecError)
    if folder is not None and "/" not in name and not name.endswith(".toml"):
        entry = resources.files("stairbot.inputs").joinpath(folder, f"{name}.toml")
        if entry.is_file():
            return entry.read_text("utf-8")
    raise SpecError(src, f"sweep.{key}", f"{name!r}: no such file (relative to the spec)"
                    + (", nor a shipped scenario" if folder else ""))


def _config_text(spec_dir: Path, name: str, src: str, key: str = "sweep.config") -> str:
    """The robot config a spec names (a file beside it, or a shipped robot), as
    one TOML document with what it extends laid in."""
    beside = spec_dir / name
    try:
        return tomlw.dumps(config_table(beside if beside.is_file() else name))
    except ConfigError as exc:
        raise SpecError(src, key, str(exc)) from None


def _scenario_robot(spec_dir: Path, name: str | None, text: str,
                    src: str) -> tuple[str, str | None]:
    """The base scenario's text without its ``robot`` key, and that robot's
    config as :func:`_config_text` gives it (None: the scenario names none).
    A robot file is read beside the base scenario."""
    raw = load_toml(text, src, SpecError)
    robot = raw.pop("robot", None)
    if robot is None:
        return text, None
    if not isinstance(robot, str) or not robot:
        raise SpecError(src, "sweep.scenario", f"its robot {robot!r} is not allowed; allowed: "
                        "a shipped robot's name or a robot config file's path")
    folder = (spec_dir / name).parent if name is not None and (spec_dir / name).is_file() \
        else spec_dir
    return tomlw.dumps(raw), _config_text(folder, robot, src, "sweep.scenario")


def with_config(spec: Spec, name: str) -> Spec:
    """``spec`` run with another robot config (``stairbot sweep --config``): a
    file, or a shipped robot's name.  Raises SpecError."""
    text = _config_text(Path.cwd(), name, spec.source)
    return replace(spec, config_text=text)


def parse_spec(text: str, source: str, spec_dir: Path | None = None) -> Spec:
    """Parse a spec document; the cases themselves are checked by
    :func:`stairbot.sweep.cases.check_spec`.  Raises SpecError."""
    raw = load_toml(text, source, SpecError)
    data = convert(raw, SpecFile, source, SpecError)
    check_line(data.sweep.name, source, "sweep.name", SpecError)
    check_line(data.sweep.description, source, "sweep.description", SpecError)
    if data.sweep.name is not None and ("/" in data.sweep.name or "\\" in data.sweep.name):
        raise SpecError(source, "sweep.name", f"{data.sweep.name!r} names the results folder; "
                        "allowed: a name without / or \\")
    axes = [parse_axis(source, p, v) for p, v in flatten(data.axes)]
    seen = [a.path for a in axes]
    for path in seen:
        if seen.count(path) > 1:
            raise SpecError(source, f"axes.{path}", "given twice; allowed: once")
    for key in ("x", "y"):
        wanted = getattr(data.report, key)
        if wanted is not None and wanted not in seen and wanted not in DERIVED:
            raise SpecError(source, f"report.{key}", f"{wanted!r} is not an axis of this spec; "
                            f"allowed: {', '.join([*seen, *DERIVED])}")
    spec_dir = spec_dir or Path(source).parent
    s = data.sweep
    scenario_text = _base_text(spec_dir, s.scenario, source, "scenario",
                               "default_scenario.toml", "scenarios")
    # the robot the base scenario names runs the cases, unless the spec names one
    scenario_text, robot_text = _scenario_robot(spec_dir, s.scenario, scenario_text, source)
    config_text = robot_text if s.config is None else _config_text(spec_dir, s.config, source)
    v = data.verdict
    spec = Spec(source=source, name=s.name or printable(Path(source).stem),
                description=s.description, seed=s.seed, samples=s.cases, axes=tuple(axes),
                rules=Rules(v.rise_margin_m, v.tread_margin_m, v.home_m),
                scenario_text=scenario_text, config_text=config_text, report=data.report,
                raw=raw)
    _check_size(spec)
    return spec


def _check_size(spec: Spec) -> None:
    """Refuse a spec of more than MAX_CASES cases (counted, none built)."""
    if spec.total <= MAX_CASES:
        return
    if spec.samples_per_point > 1:
        fields = "axes, sweep.cases"
        count = (f"{spec.grid_size} grid point(s) x {spec.samples} case(s) each = "
                 f"{spec.total} cases")
    else:
        fields, count = "axes", f"{spec.grid_size} grid points"
    raise SpecError(spec.source, fields, f"{count}; allowed: at most {MAX_CASES} cases in "
                    "a sweep (fewer grid values, or fewer samples per point)")


DERIVED = ("max_rise_m", "min_tread_m", "count")
"""Values every case records beside its axes (usable as heat-map axes)."""


def load_spec(path: str | Path) -> Spec:
    """Load a spec file.  Raises SpecError (unreadable, not TOML, bad field)."""
    p = Path(path)
    text = read_text(p, SpecError)
    return parse_spec(text, str(p), p.parent)
