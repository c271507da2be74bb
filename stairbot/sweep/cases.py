"""Cases: a case index becomes a scenario TOML (and a robot config TOML when
the spec overrides the robot), built and validated by the same loaders that
``stairbot run --scenario/--config`` use, so what a sweep runs is what a person
reproduces from the files it writes.

:func:`check_spec` builds every case (or the first ``limit``) before any
runs, one at a time: a value the loaders refuse (and the edges of every
distribution) stops the sweep with a SpecError naming the axis.  How many
cases a spec makes is counted from its axes (:attr:`Spec.total`), without
building any.
"""

from __future__ import annotations

import copy
import math
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from functools import cache
from importlib import resources
from typing import Any

import msgspec

from stairbot.control.algorithm import limits
from stairbot.control.robot_config import parse_config
from stairbot.errors import ConfigError, ScenarioError
from stairbot.inputs.config import DEFAULT_CONFIG_NAME, RobotConfig
from stairbot.inputs.scenario import (
    DEFAULT_COUNT,
    DEFAULT_RISE,
    DEFAULT_TREAD,
    Scenario,
    Step,
    parse_scenario,
)
from stairbot.inputs.schema import _tokens
from stairbot.sweep import tomlw
from stairbot.sweep.spec import VIRTUAL, Axis, Rules, Spec, SpecError, case_rng

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


SIGHT_MARGIN_M = 0.02
"""The band either side of LENGTH_OF_INFINITY in which the start's nearer
front sensor may or may not read the first riser as nearer (the noise of one
reading, or three of the sensor's stated sigma there if that is more)."""


def first_sight(scenario: Scenario, config: RobotConfig) -> float:
    """The nearer front sensor's reading at the start pose, before noise (inf:
    nothing in range): what the simulated beams meet -- one level ray each,
    or a cone as the sensor model combines it, so a cone tilted up that takes
    in the risers beyond the first reads long.  The calibration's case 1 stops
    the robot, rightly, when both read LENGTH_OF_INFINITY or more: stairs that
    far are not in sight, whatever their steps."""
    from stairbot.fakes.plan import Plan
    from stairbot.fakes.sim_sensors import SimSensors  # the sweep runs the sim anyway
    from stairbot.fakes.world import World

    world = World(config, scenario)
    plan = Plan(scenario.width, scenario.side_wall, y=scenario.start.lateral,
                yaw=math.radians(scenario.start.yaw_deg))
    right, left = SimSensors(config, scenario, world, plan).front_seen()
    hi = config.sensors.range(back=False)[1]
    seen = [d for d in (right, left) if d is not None and d <= hi]
    return min(seen, default=math.inf)


def sight_margin(config: RobotConfig) -> float:
    """How far either side of LENGTH_OF_INFINITY the sight rule leaves a band."""
    far = config.LENGTH_OF_INFINITY
    return max(SIGHT_MARGIN_M, 3.0 * config.sensors.sigma(False, far))


def zone(scenario: Scenario, config: RobotConfig, rules: Rules) -> tuple[str, float, float]:
    """("inside" | "band" | "outside", max rise, min tread) of the steps the robot
    attempts (the first max_steps) against its limits (rises between
    min_step_rise_m and max_step_rise_m, each at least min_rise_for the
    tread before it and, where that tread is measured (all but a landing's),
    min_rise_for the tread after it; treads of min_tread_m or more), give
    or take the margins; stairs out of sight at the start (see
    :func:`first_sight`) are outside.
    A tread counts where the robot must fit on it: every tread it climbs onto,
    but not the last one under a landing, which runs on into the landing.
    A tread so long that the next riser is out of the front pair's sight at
    ascent 8 ends the flight for the robot, as stairs out of sight at the
    start do (:func:`_riser_seen_m`)."""
    if scenario.start.on == "top":
        return descent_zone(scenario, config, rules)
    if scenario.landing is not None:
        return landing_zone(scenario, config, rules)
    steps = scenario.steps[:config.algorithm.max_steps]
    if not steps:
        return "inside", 0.0, math.inf
    max_rise = max(s.rise for s in steps)
    min_rise = min(s.rise for s in steps)
    last = len(scenario.steps) - 1
    treads = [s.tread for i, s in enumerate(steps) if not (i == last and scenario.top == "landing")]
    min_tread = min(treads, default=math.inf)
    lr, lo, lt = config.max_step_rise_m, limits.min_step_rise_m(config), limits.min_tread_m(config)
    rm, tm = rules.rise_margin_m, rules.tread_margin_m
    # how far each riser clears what the front cone needs to measure the tread
    # before it, and each measured tread's own riser what the robot asks of it
    # (it takes the next riser to be as high: ascent 3)
    measured = [i for i in range(len(steps)) if not (i == last and scenario.top == "landing")]
    near_low, far_low = _cone_clearances(scenario, steps, measured, config, tm)
    low = min([min_rise - lo] + near_low)
    sight, margin = first_sight(scenario, config), sight_margin(config)
    sight = max([sight] + [_riser_seen_m(s.tread, config) for s in steps[:-1]])
    far = config.LENGTH_OF_INFINITY
    if (max_rise > lr + rm or low < -rm or min_tread < lt - tm
            or sight > far + margin):
        return "outside", max_rise, min_tread
    if (max_rise <= lr - rm and low >= rm and min(far_low, default=rm) >= rm
            and min_tread >= lt + tm and sight <= far - margin):
        return "inside", max_rise, min_tread
    return "band", max_rise, min_tread


def _riser_seen_m(tread: float, config: RobotConfig) -> float:
    """What the front pair reads of the next riser at ascent 8 on a tread
    ``tread`` long: from segment 1's front face, about LENGTH_OF_FIRST_MODULE
    + LENGTH_OF_SECOND_MODULE - TAB_PAST_EDGE_M past the edge.  Past
    LENGTH_OF_INFINITY (give or take the sight margin) the robot takes that
    step for the top: like stairs out of sight at the start, the rest is
    outside."""
    from stairbot.control.algorithm.landing import TAB_PAST_EDGE_M

    return tread - (config.LENGTH_OF_FIRST_MODULE + config.LENGTH_OF_SECOND_MODULE
                    - TAB_PAST_EDGE_M)


def _cone_clearances(scenario: Scenario, steps: tuple[Step, ...] | list[Step],
                     measured: list[int], config: RobotConfig, tm: float
                     ) -> tuple[list[float], list[float]]:
    """How far each riser clears what the front cone needs, split by the
    rule that holds it: ([the rule's own, which refuses], [the readings',
    for a tread past FAR_TREAD_M]).  A tread the robot measures up to
    FAR_TREAD_M (the reading, tread + approach_gap, give or take the tread
    margin) holds the riser it climbs, and the next, to min_rise_for it;
    past it the robot climbs a riser lower than that if its readings held
    as segment 1 rose (:mod:`stairbot.control.algorithm.long_tread`): the next
    riser lower than min_rise_for, climbing and refusing are both right (a
    wall is higher than any: no bound).  Within the margin of FAR_TREAD_M,
    either rule may hold: the readings'."""
    from stairbot.control.algorithm.long_tread import (
        FAR_TREAD_M,  # the sweep runs the controller anyway
    )

    near: list[float] = []
    far: list[float] = []
    gap = config.algorithm.approach_gap
    for i in range(len(steps)):
        tread = steps[i].tread
        need = config.min_rise_for(tread)
        ahead = [steps[i + 1].rise - need] if i + 1 < len(steps) else []
        own = [steps[i].rise - need] if i in measured else []
        if tread + gap <= FAR_TREAD_M - tm:
            near.extend(ahead + own)
        elif tread + gap <= FAR_TREAD_M + tm:
            far.extend(ahead + own)  # either rule
        else:
            far.extend(ahead)  # a wall ahead (the last step under top = "wall"): no bound
    return near, far


LATERAL_DRIFT_M = 0.05
"""How far across the flight a climb may carry the robot from where it
started: calibration squares up within its tolerance (a degree or so), and
1.3 degrees over three steps and the landing's approach moved it 45 mm."""


def landing_zone(scenario: Scenario, config: RobotConfig, rules: Rules
                 ) -> tuple[str, float, float]:
    """Quarter-turn stairs' zone: each flight's as a flight of its own
    (:func:`zone`: the first ends on the landing, the second on its top),
    and the landing's.  The robot turns on the landing only if it has the
    side pair and ``[algorithm] landings``, the second flight has steps, the
    landing is not so deep that the wall ahead reads as the top (the front
    pair's LENGTH_OF_INFINITY past the robot standing at the edge), and the
    robot's turning room (:func:`~stairbot.control.algorithm.landing.turn_room_m`)
    fits in half the landing's measured depth and on either side of where it
    climbed (half the width, less start.lateral), give or take the tread
    margin.  Where the landing refuses, the first flight's zone stands: the
    robot climbs it, refuses the landing, comes home, and that is right
    ("refused"); where it does not, both flights must be climbed."""
    from stairbot.control.algorithm.landing import DEPTH_MARGIN, turn_room_m

    landing = scenario.landing
    assert landing is not None
    first = _first_flight_zone(scenario, config, rules)
    if not landing.steps:
        return first  # a wall where the second flight should be: the flight ends there
    second = zone(replace(scenario, steps=landing.steps, landing=None,
                          start=msgspec.structs.replace(scenario.start, distance=0.3)),
                  config, rules)
    tm = rules.tread_margin_m
    room = turn_room_m(config)
    depth = landing.depth - DEPTH_MARGIN
    # where the robot stands across the landing: start.lateral, and what
    # calibration's residual yaw adds over the flight (LATERAL_DRIFT_M)
    centred = scenario.width / 2.0 - room
    drifted = centred - abs(scenario.start.lateral) - LATERAL_DRIFT_M
    # how far inside LENGTH_OF_INFINITY ascent 8 reads the wall ahead
    top = config.LENGTH_OF_INFINITY - _riser_seen_m(landing.depth, config)
    sight = sight_margin(config)
    turns = config.algorithm.landings and config.sensors.has_side_pair
    max_rise, min_tread = max(first[1], second[1]), min(first[2], second[2])
    steps = len(scenario.steps) + len(landing.steps)
    if not turns or min(depth / 2.0 - room, centred) < -tm or top < -sight:
        # the landing refuses (or reads as the top): the first flight decides
        return ("outside" if first[0] == "inside" else first[0]), max_rise, min_tread
    short = min(depth / 2.0 - room, drifted)
    zones = {first[0], second[0]}
    if "outside" in zones:
        return "outside", max_rise, min_tread
    if zones == {"inside"} and short >= tm and top >= sight \
            and steps <= config.algorithm.max_steps:
        return "inside", max_rise, min_tread
    return "band", max_rise, min_tread


def _first_flight_zone(scenario: Scenario, config: RobotConfig, rules: Rules
                       ) -> tuple[str, float, float]:
    """The first flight's zone under a quarter-turn landing: its last tread is
    the landing, which ascent 3 measures (and holds to min_rise_for, as any
    tread: the robot cannot tell the landing's wall from a low riser beyond
    a long tread) where the wall ahead is in the front pair's sight (nearer
    than LENGTH_OF_INFINITY, give or take the sight margin), and does not
    beyond it; between, either."""
    landing = scenario.landing
    assert landing is not None
    last = scenario.steps[-1]
    walled = replace(scenario, landing=None, top="wall",
                     steps=(*scenario.steps[:-1], type(last)(last.rise, landing.depth)))
    open_ = replace(scenario, landing=None)
    reading = landing.depth + config.algorithm.approach_gap
    sight, far = sight_margin(config), config.LENGTH_OF_INFINITY
    if reading < far - sight:
        return zone(walled, config, rules)
    if reading > far + sight:
        return zone(open_, config, rules)
    a, b = zone(walled, config, rules), zone(open_, config, rules)
    return a if a[0] == b[0] else ("band", a[1], min(a[2], b[2]))


def descent_zone(scenario: Scenario, config: RobotConfig, rules: Rules
                 ) -> tuple[str, float, float]:
    """A continuous descent's zone: every rise from the least drop the back
    pair reads as one (:func:`~stairbot.control.algorithm.edge.edge_drop_m` less
    BACK_CLEARANCE) to max_step_rise_m, and every tread it steps down onto (all
    but the top one, which runs on into the landing it starts on) at least
    LENGTH_OF_A_ROBOT + SAFE_LENGTH (narrow steps or not), give or take the
    margins, is inside; a rise deeper than
    max_drop_m (what segment 3 can be lowered), a lower rise than the pair
    sees, or a tread shorter than LENGTH_OF_FIRST_MODULE +
    LENGTH_OF_SECOND_MODULE (segments 1 and 2 do not fit on it), is outside
    (refused); between, the band.  (The robot does not measure a tread
    before it steps down onto it: one shorter than min_tread_m it descends
    while its back pair still reads the tread after the step, and refuses
    once it reads past the next edge.)"""
    from stairbot.control.algorithm.edge import edge_drop_m  # the sweep runs the controller anyway

    steps = scenario.steps
    low = edge_drop_m(config, from_top=True) - config.BACK_CLEARANCE  # the least drop seen
    max_rise = max(s.rise for s in steps)
    min_rise = min(s.rise for s in steps)
    min_tread = min((s.tread for s in steps[:-1]), default=math.inf)
    rm, tm = rules.rise_margin_m, rules.tread_margin_m
    if (max_rise > config.max_drop_m + rm or min_rise < low - rm
            or min_tread < config.LENGTH_OF_FIRST_MODULE + config.LENGTH_OF_SECOND_MODULE - tm):
        return "outside", max_rise, min_tread
    # the whole robot's tread, narrow steps or not: a continuous descent does
    # not know a tread before it steps down onto it
    whole = config.LENGTH_OF_A_ROBOT + config.SAFE_LENGTH
    if (max_rise <= config.max_step_rise_m - rm and min_rise >= low + rm
            and min_tread >= whole + tm):
        return "inside", max_rise, min_tread
    return "band", max_rise, min_tread


def build_case(spec: Spec, index: int, override: tuple[str, Any] | None = None) -> Case:
    """Case ``index`` (with one axis forced to a value, to check a distribution's
    edges).  Raises SpecError when the loaders refuse what the axes make."""
    values = {p: _round(v) for p, v in spec.axis_values(index).items()}
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
            _set(target, sub, value)
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
        "limit_rise_m": round(config.max_step_rise_m, DIGITS),
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
