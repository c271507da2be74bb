"""Scenarios: the stairs, the start pose, sensor noise, faults and the expected end.

A scenario is a TOML file (schema in docs/scenarios.md).  Parsing is strict:
unknown keys, wrong types and impossible values raise
:class:`~stairbot.errors.ScenarioError` naming the file, the field and what is
allowed.  The parsed :class:`Scenario` is plain data the simulation builds from.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Annotated, Literal

import msgspec

from stairbot.errors import ScenarioError

Pos = Annotated[float, msgspec.Meta(gt=0)]
NonNeg = Annotated[float, msgspec.Meta(ge=0)]
SensorName = Literal["SFR", "SFL", "SBR", "SBL"]
Outcome = Literal["completed", "stopped", "error", "fell"]
AscentEnd = Literal["top_reached", "obstacle", "step_limit"]


class Step(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    rise: Pos
    tread: Pos


class Stairs(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    count: Annotated[int, msgspec.Meta(ge=0, le=40)] | None = None
    rise: Pos | None = None
    tread: Pos | None = None
    steps: list[Step] | None = None
    top: Literal["landing", "wall"] = "landing"
    width: Pos = 1.0
    side_wall: Literal["none", "left", "right", "both"] = "none"


class Start(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    distance: Pos = 0.5
    yaw_deg: Annotated[float, msgspec.Meta(ge=-80, le=80)] = 0.0
    lateral: float = 0.0


class Sensors(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    noise: NonNeg = 0.001
    seed: int = 1


class Fault(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    at: NonNeg
    sensor: SensorName
    kind: Literal["offset", "error"]
    offset: float = 0.0
    duration: Pos | None = None


class Expect(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    outcome: Outcome | None = None
    ascent_end: AscentEnd | Literal["none"] | None = None
    steps_climbed: Annotated[int, msgspec.Meta(ge=0)] | None = None
    steps_descended: Annotated[int, msgspec.Meta(ge=0)] | None = None
    pauses: Annotated[int, msgspec.Meta(ge=0)] | None = None
    error_contains: str | None = None
    max_final_offset_m: Pos | None = None


class ScenarioFile(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    name: str | None = None
    description: str | None = None
    stairs: Stairs = msgspec.field(default_factory=Stairs)
    start: Start = msgspec.field(default_factory=Start)
    sensors: Sensors = msgspec.field(default_factory=Sensors)
    faults: list[Fault] = msgspec.field(default_factory=list)
    expect: Expect | None = None


@dataclass(frozen=True)
class Scenario:
    """A validated scenario with the stairs resolved to a list of steps."""

    source: str
    name: str
    description: str
    steps: tuple[Step, ...]
    top: str
    width: float
    side_wall: str
    start: Start
    sensors: Sensors
    faults: tuple[Fault, ...]
    expect: Expect | None


DEFAULT_STAIRS = Stairs(count=5, rise=0.17, tread=0.28)


def _split(message: str) -> tuple[str | None, str]:
    if " - at `" in message:
        problem, _, rest = message.partition(" - at `")
        field = rest.rstrip("`").removeprefix("$").lstrip(".")
        return field or None, problem
    return None, message


def parse_scenario(text: str, source: str) -> Scenario:
    """Parse and validate a scenario document.  Raises ScenarioError."""
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(source, None, f"not valid TOML: {exc}") from None
    try:
        data = msgspec.convert(raw, ScenarioFile, strict=True)
    except msgspec.ValidationError as exc:
        field, problem = _split(str(exc))
        if problem.startswith("Object contains unknown field"):
            problem = f"unknown key {problem.split('`')[1]!r}; the schema is in docs/scenarios.md"
        raise ScenarioError(source, field, problem) from None
    return _resolve(data, source)


def _resolve(data: ScenarioFile, source: str) -> Scenario:
    st = data.stairs
    if st.steps is not None:
        if st.count is not None or st.rise is not None or st.tread is not None:
            raise ScenarioError(source, "stairs.steps",
                                "give either steps = [...] or count + rise + tread, not both")
        steps = tuple(st.steps)
    else:
        count = 5 if st.count is None else st.count
        if count > 0 and (st.rise is None or st.tread is None):
            missing = "rise" if st.rise is None else "tread"
            raise ScenarioError(source, f"stairs.{missing}",
                                "required with count > 0 (a length in metres, > 0)")
        steps = tuple(Step(st.rise or 0.0, st.tread or 0.0) for _ in range(count))
    if steps and st.top == "wall" and len(steps) == 0:
        raise ScenarioError(source, "stairs.top", "a wall needs at least one step")
    for fi, fault in enumerate(data.faults):
        if fault.kind == "offset" and fault.offset == 0.0:
            raise ScenarioError(source, f"faults[{fi}].offset",
                                "an offset fault needs a non-zero offset in metres")
    half = st.width / 2
    if abs(data.start.lateral) >= half:
        raise ScenarioError(source, "start.lateral",
                            f"{data.start.lateral} m puts the robot off the flight; "
                            f"allowed: between -{half} and {half} m (half the width)")
    return Scenario(
        source=source,
        name=data.name or Path(source).stem,
        description=data.description or "",
        steps=steps,
        top=st.top,
        width=st.width,
        side_wall=st.side_wall,
        start=data.start,
        sensors=data.sensors,
        faults=tuple(data.faults),
        expect=data.expect,
    )


def load_scenario(path: str | Path | None = None) -> Scenario:
    """Load a scenario file, or the default stairs when ``path`` is None."""
    if path is None:
        text = resources.files("stairbot").joinpath("default_scenario.toml").read_text("utf-8")
        return parse_scenario(text, "<default scenario>")
    p = Path(path)
    try:
        text = p.read_text("utf-8")
    except OSError as exc:
        raise ScenarioError(str(p), None, f"cannot read: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise ScenarioError(str(p), None, "not a UTF-8 text file") from None
    return parse_scenario(text, str(p))
