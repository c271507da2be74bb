"""Scenarios: the stairs, the start pose, sensor noise, faults and the expected end.

A scenario is a TOML file (schema in docs/scenarios.md).  Parsing is strict:
unknown keys, wrong types and impossible values raise
:class:`~stairbot.errors.ScenarioError` naming the file, the field and what is
allowed.  The parsed :class:`Scenario` is plain data the simulation builds from.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

import msgspec

from stairbot.errors import ScenarioError
from stairbot.files import is_file, shown
from stairbot.inputs.config import shipped_configs
from stairbot.inputs.schema import convert, load_toml, read_named, shipped
from stairbot.text import check_line, printable

# Bounds that keep the simulated world sane (docs/scenarios.md): a riser from
# 5 mm to 1 m, a tread from 1 cm to 10 m, a flight from 0.1 to 20 m wide.
Rise = Annotated[float, msgspec.Meta(ge=0.005, le=1.0)]
Tread = Annotated[float, msgspec.Meta(ge=0.01, le=10.0)]
Seconds = Annotated[float, msgspec.Meta(ge=0, le=86400.0)]
SensorName = Literal["SFR", "SFL", "SBR", "SBL", "SSR", "SSL"]
Outcome = Literal["completed", "stopped", "error", "fell", "came_home_degraded"]
AscentEnd = Literal["top_reached", "obstacle", "step_limit", "landing_closed",
                    "landing_too_small"]


class Step(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    rise: Rise
    tread: Tread


class Stairs(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    count: Annotated[int, msgspec.Meta(ge=0, le=40)] | None = None
    rise: Rise | None = None
    tread: Tread | None = None
    steps: Annotated[list[Step], msgspec.Meta(max_length=40)] | None = None
    top: Literal["landing", "wall"] = "landing"
    width: Annotated[float, msgspec.Meta(ge=0.1, le=20.0)] = 1.0
    side_wall: Literal["none", "left", "right", "both"] = "none"


class Landing(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    """A quarter-turn landing at the top of the flight, and the second flight
    that leaves it to the left or right (the seed's extension 1)."""

    depth: Annotated[float, msgspec.Meta(ge=0.1, le=10.0)] = 1.0
    """From the top edge of the first flight to the wall ahead, m.  The landing
    is as wide as the first flight (``stairs.width``); the second flight is
    ``depth`` wide."""
    turn: Literal["left", "right"] = "left"
    """The side the second flight leaves the landing on; the other side, and
    the far side, are walls."""
    count: Annotated[int, msgspec.Meta(ge=0, le=40)] = 3
    """Steps of the second flight; 0: a wall where it should be."""
    rise: Rise | None = None
    """Of the second flight's steps (default: the first flight's last step's)."""
    tread: Tread | None = None


@dataclass(frozen=True)
class TurnLanding:
    """A resolved :class:`Landing`: the second flight as a list of steps."""

    depth: float
    turn: str  # "left" | "right"
    steps: tuple[Step, ...]


MAX_START_DISTANCE = 20.0
"""Farthest start before the first riser, m (the simulated floor runs 30 m back)."""
TOP_LANDING_ROOM = 2.0
"""Farthest start from the top edge, m, on the top (the simulated landing runs
3 m past the last riser's top: the robot, 0.2-0.5 m long, stays on it)."""


class Start(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    on: Literal["floor", "top"] = "floor"
    """Where the robot starts: on the floor before the first riser, facing the
    stairs; or on the top of the flight, facing away from it, to back down it
    (continuous descent: a flight it has not climbed)."""
    distance: Annotated[float, msgspec.Meta(gt=0, le=MAX_START_DISTANCE)] = 0.5
    """On the floor: the robot's front face to the first riser.  On the top:
    its rear (segment 3's back face) to the top edge."""
    yaw_deg: Annotated[float, msgspec.Meta(ge=-80, le=80)] = 0.0
    lateral: Annotated[float, msgspec.Meta(ge=-10.0, le=10.0)] = 0.0


class Sensors(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    noise: Annotated[float, msgspec.Meta(ge=0, le=1.0)] = 0.001
    seed: int = 1
    outliers: Annotated[float, msgspec.Meta(ge=0, le=0.5)] = 0.0
    """Share of measurements replaced by a value anywhere within range (on top
    of the sensor model's own rate, if it has one)."""


class Fault(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    at: Seconds
    sensor: SensorName
    kind: Literal["offset", "error", "freeze", "stuck"]
    offset: Annotated[float, msgspec.Meta(ge=-10.0, le=10.0)] = 0.0
    duration: Annotated[float, msgspec.Meta(gt=0, le=86400.0)] | None = None


class Expect(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    outcome: Outcome | None = None
    ascent_end: AscentEnd | Literal["none"] | None = None
    steps_climbed: Annotated[int, msgspec.Meta(ge=0)] | None = None
    steps_descended: Annotated[int, msgspec.Meta(ge=0)] | None = None
    pauses: Annotated[int, msgspec.Meta(ge=0)] | None = None
    error_contains: str | None = None
    max_final_offset_m: Annotated[float, msgspec.Meta(gt=0, le=100.0)] | None = None


class ScenarioFile(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    name: str | None = None
    description: str | None = None
    robot: str | None = None
    stairs: Stairs = msgspec.field(default_factory=Stairs)
    start: Start = msgspec.field(default_factory=Start)
    sensors: Sensors = msgspec.field(default_factory=Sensors)
    faults: list[Fault] = msgspec.field(default_factory=list)
    expect: Expect | None = None
    landing: Landing | None = None


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
    landing: TurnLanding | None = None
    """A quarter-turn landing at the top of the flight, or None: the flight
    ends on a straight landing (``top``)."""
    robot: str | None = None
    """The robot config the scenario is written for, as ``--config`` takes it:
    a shipped robot's name, or a config file's path (one relative to the
    scenario's folder made whole).  A run without ``--config`` uses it; None:
    the reference robot."""


DEFAULT_COUNT, DEFAULT_RISE, DEFAULT_TREAD = 5, 0.17, 0.28
DEFAULT_STAIRS = Stairs(count=DEFAULT_COUNT, rise=DEFAULT_RISE, tread=DEFAULT_TREAD)


def parse_scenario(text: str, source: str) -> Scenario:
    """Parse and validate a scenario document.  Raises ScenarioError naming the
    file, the field and what it allows."""
    raw = load_toml(text, source, ScenarioError)
    return _resolve(convert(raw, ScenarioFile, source, ScenarioError), source)


def _resolve(data: ScenarioFile, source: str) -> Scenario:
    check_line(data.name, source, "name", ScenarioError)
    check_line(data.description, source, "description", ScenarioError)
    robot = _robot(data.robot, source)
    st = data.stairs
    if st.steps is not None:
        if st.count is not None or st.rise is not None or st.tread is not None:
            raise ScenarioError(source, "stairs.steps",
                                "give either steps = [...] or count + rise + tread, not both")
        steps = tuple(st.steps)
    else:
        # a key left out takes the default stairs' value
        count = DEFAULT_COUNT if st.count is None else st.count
        step = Step(DEFAULT_RISE if st.rise is None else st.rise,
                    DEFAULT_TREAD if st.tread is None else st.tread)
        steps = tuple(step for _ in range(count))
    if st.top == "wall" and not steps:
        raise ScenarioError(source, "stairs.top",
                            "'wall' needs at least one step; open floor is count = 0 "
                            "with top = 'landing'")
    for fi, fault in enumerate(data.faults):
        if fault.kind == "offset" and fault.offset == 0.0:
            raise ScenarioError(source, f"faults[{fi}].offset",
                                "an offset fault needs a non-zero offset in metres")
        if fault.kind != "offset" and fault.offset != 0.0:
            raise ScenarioError(source, f"faults[{fi}].offset",
                                f"only an 'offset' fault takes an offset; an '{fault.kind}' "
                                "fault makes the sensor report ERROR ('error'), stop "
                                "measuring ('freeze') or repeat its last measurement as "
                                "new ('stuck'); leave offset out")
    if data.start.on == "top":
        if not steps:
            raise ScenarioError(source, "start.on",
                                "'top' needs at least one step to stand on the top of; "
                                "allowed: 'floor', or 'top' with stairs.count >= 1")
        if st.top == "wall":
            raise ScenarioError(source, "start.on",
                                "'top' needs the flight to end on a landing (stairs.top = "
                                "'landing'): with a wall there is no top to stand on")
        exp = data.expect
        if exp is not None and (exp.steps_climbed or exp.ascent_end not in (None, "none")):
            raise ScenarioError(source, "expect",
                                "a robot that starts on the top climbs nothing: leave out "
                                "steps_climbed (or 0) and ascent_end (or 'none')")
        if data.start.distance > TOP_LANDING_ROOM:
            raise ScenarioError(source, "start.distance",
                                f"{data.start.distance} m from the top edge leaves the robot "
                                f"off the landing; allowed with start.on = 'top': up to "
                                f"{TOP_LANDING_ROOM} m")
    landing = _landing(data, steps, source)
    half = st.width / 2
    if abs(data.start.lateral) >= half:
        raise ScenarioError(source, "start.lateral",
                            f"{data.start.lateral} m puts the robot off the flight; "
                            f"allowed: between -{half} and {half} m (half the width)")
    return Scenario(
        source=source,
        name=data.name or printable(Path(source).stem),  # a name holds no control character
        description=data.description or "",
        steps=steps,
        top=st.top,
        width=st.width,
        side_wall=st.side_wall,
        start=data.start,
        sensors=data.sensors,
        faults=tuple(data.faults),
        expect=data.expect,
        landing=landing,
        robot=robot,
    )


def _robot(value: str | None, source: str) -> str | None:
    """The scenario's ``robot``: a shipped robot's name as given, or the path
    of a config file (relative to the scenario's folder when the scenario is
    a file, else to the working directory).  Raises ScenarioError when it is
    neither; the config itself is read when a run loads it."""
    if value is None:
        return None
    check_line(value, source, "robot", ScenarioError)
    allowed = ("allowed: a shipped robot's name (" + ", ".join(shipped_configs())
               + ") or a robot config file's path (relative to the scenario's folder)")
    folder = Path(source).parent if is_file(source) else Path()
    path = folder / value
    if value and is_file(path) and not path.is_dir():
        return str(path)
    if value in shipped_configs():
        return value
    named = "/" not in value and "\\" not in value and not value.endswith(".toml")
    what = ("empty" if not value else "neither a shipped robot nor a file" if named
            else f"no such file ({shown(path)})")
    raise ScenarioError(source, "robot", f"{printable(repr(value))}: {what}; {allowed}")


def _landing(data: ScenarioFile, steps: tuple[Step, ...], source: str) -> TurnLanding | None:
    """The scenario's quarter-turn landing, checked against its stairs."""
    ld = data.landing
    if ld is None:
        return None
    if not steps:
        raise ScenarioError(source, "landing",
                            "a landing needs a flight to stand at the top of; allowed: "
                            "stairs.count >= 1, or leave [landing] out")
    if data.stairs.top == "wall":
        raise ScenarioError(source, "landing",
                            "the flight ends in a wall (stairs.top = 'wall'), not on a "
                            "landing; allowed: stairs.top = 'landing' with [landing]")
    if data.start.on == "top":
        raise ScenarioError(source, "landing",
                            "a robot that starts on the top does not climb to a landing; "
                            "allowed: start.on = 'floor' with [landing]")
    last = steps[-1]
    step = Step(last.rise if ld.rise is None else ld.rise,
                last.tread if ld.tread is None else ld.tread)
    return TurnLanding(ld.depth, ld.turn, tuple(step for _ in range(ld.count)))


SHIPPED_DIR = "scenarios"


def shipped_scenarios() -> list[str]:
    """Names of the scenarios shipped with stairbot (``--scenario NAME``)."""
    return shipped(SHIPPED_DIR)


def load_scenario(path: str | Path | None = None) -> Scenario:
    """Load a scenario file, a shipped scenario by name (``"wall_at_top"``: a
    plain word that is no existing file), or the default stairs when ``path``
    is None.  Raises ScenarioError."""
    if path is None:
        entry = resources.files("stairbot.inputs").joinpath("default_scenario.toml")
        text = entry.read_text("utf-8")
        return parse_scenario(text, "<default scenario>")
    return parse_scenario(*read_named(path, SHIPPED_DIR, "scenario", ScenarioError))


def expectation_mismatches(expect: Expect | None, result: Mapping[str, Any]) -> list[str]:
    """Compare a run's result (``RunResult.to_dict()``) with ``[expect]``.

    Returns one line per field that differs (empty: the run ended as expected).
    Without ``[expect]`` the run is expected to complete.
    """
    if expect is None:
        expect = Expect(outcome="completed")
    out: list[str] = []
    for name in ("outcome", "steps_climbed", "steps_descended", "pauses"):
        want = getattr(expect, name)
        if want is not None and result.get(name) != want:
            out.append(f"{name}: expected {want!r}, got {result.get(name)!r}")
    if expect.ascent_end is not None:
        want_end = None if expect.ascent_end == "none" else expect.ascent_end
        if result.get("ascent_end") != want_end:
            out.append(f"ascent_end: expected {want_end!r}, got {result.get('ascent_end')!r}")
    if expect.error_contains is not None:
        err = result.get("error") or ""
        if expect.error_contains.lower() not in str(err).lower():
            out.append(f"error: expected text containing {expect.error_contains!r}, got {err!r}")
    if expect.max_final_offset_m is not None:
        off = result.get("final_offset_m")
        if off is None or off > expect.max_final_offset_m:
            out.append(f"final_offset_m: expected at most {expect.max_final_offset_m}, got {off!r}")
    return out
