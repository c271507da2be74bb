"""``stairbot sweep SPEC --boundary AXIS``: what to search and what the robot
publishes.

* **The axis and its range.**  An axis of the spec with a numeric range (a
  list or ``range`` of two or more numbers: those values are the scan; a
  ``uniform``, ``normal`` (mean +- 2 sd) or ``randint``: ``--scan`` values
  across it), or ``stairs.rise`` / ``stairs.tread`` when the spec holds them
  at one value or not at all: the range then spans the robot's published
  limits: the rise from 10 mm (:data:`LOWEST_RISE_M`) to ``max_step_rise_m``
  + 30 mm, the tread ``min_tread_m`` +- 60 mm.
* **The points.**  The other axes stay as the spec makes them: a search for
  every combination of the other grid axes' values (at most
  :data:`MAX_POINTS`), each sampled axis at that grid point's first draw.
* **The published limits** along the axis at each point: where the case's
  zone (:mod:`stairbot.sweep.zones`, with zero margins) changes, found
  without running anything, each named by the robot's figure it equals
  (``max_step_rise_m``, ``min_step_rise_m``, ``min_rise_for(T)``,
  ``min_tread_m``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

from stairbot.control.algorithm import limits
from stairbot.control.robot_config import load_config, parse_config
from stairbot.inputs.config import RobotConfig
from stairbot.sweep.axes import SpecError
from stairbot.sweep.cases import DIGITS, Case, build_case
from stairbot.sweep.spec import Rules, Spec

MAX_POINTS = 16
"""The most points (combinations of the other grid axes) one boundary search
runs: each is a search of its own, some 20 to 40 probes."""

DEFAULT_SCAN = 12
"""Values the scan probes across a range that is not a grid (at least)."""

SCAN_STEP_M = 0.01
"""The widest spacing of a default scan along an axis in metres: a region of
another behaviour narrower than the spacing, with the same behaviour either
side, is not seen (the reference robot strands on risers of 15 to 25 mm,
between refusals at 10 and 30 mm)."""

LIMIT_AXES = {"stairs.rise": 0.03, "stairs.tread": 0.06}
"""Axes searched across the robot's own limits when the spec gives no range:
how far past them either way."""

LOWEST_RISE_M = 0.01
"""Where a rise search starts, at the lowest (unless the low-rise rule is
lower still, less 30 mm)."""

METRE_AXES = frozenset({"stairs.rise", "stairs.tread", "stairs.width", "start.distance",
                        "start.lateral", "sensors.noise", "stairs.rise_jitter",
                        "stairs.tread_jitter"})
"""Axes in metres: their tolerance is given in millimetres."""

NAMED_WITHIN_M = 5e-4
"""A published change this near a named figure of the robot takes its name."""


@dataclass(frozen=True)
class Target:
    """What to search: the axis, its scan values, integer or not, the tolerance."""

    axis: str
    scan: tuple[float, ...]
    integer: bool
    tolerance: float
    metres: bool

    @property
    def low(self) -> float:
        return self.scan[0]

    @property
    def high(self) -> float:
        return self.scan[-1]


@dataclass(frozen=True)
class Point:
    """One search: the case index the other axes' values come from, and those values."""

    base: int
    held: dict[str, Any]


@dataclass(frozen=True)
class Published:
    """Where the verdict rules change zone along the axis, and the figure it is."""

    value: float
    below: str  # the zone just below it
    above: str
    name: str


def _number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _allowed(spec: Spec) -> list[str]:
    ranged = [a.path for a in spec.axes if _range_of(a) is not None]
    return sorted({*ranged, *LIMIT_AXES})


def _range_of(axis: Any) -> list[float] | None:
    """The values a spec axis offers a search (None: not a numeric range)."""
    if axis.kind in ("list", "range", "choice"):
        vals = list(axis.values)
        if len(set(vals)) >= 2 and all(_number(v) for v in vals):
            return sorted(float(v) for v in set(vals))
        return None
    lo, hi = axis.params
    if axis.kind == "normal":
        lo, hi = lo - 2.0 * hi, lo + 2.0 * hi
    return [float(lo), float(hi)] if hi > lo else None


def config_of(case: Case) -> RobotConfig:
    """The robot config a case runs on."""
    if case.config_text is None:
        return load_config()
    return parse_config(case.config_text, "<case config>")


def target(spec: Spec, axis: str, tolerance: float | None, scan: int | None) -> Target:
    """The search along ``axis``.  Raises SpecError naming the axes allowed."""
    where = f"--boundary {axis}"
    found = next((a for a in spec.axes if a.path == axis), None)
    values = _range_of(found) if found is not None else None
    integer = found is not None and found.kind in ("list", "range", "choice", "randint") \
        and all(isinstance(v, int) for v in (found.values or found.params)) \
        and (found.kind != "randint" or all(float(p).is_integer() for p in found.params))
    if values is None:
        if axis not in LIMIT_AXES:
            raise SpecError(spec.source, None, f"{where}: not an axis of this spec with a "
                            f"numeric range; allowed: {', '.join(_allowed(spec))}")
        integer = False
        cfg = config_of(build_case(spec, 0))
        pad = LIMIT_AXES[axis]
        if axis == "stairs.rise":
            # from a kerb's lip, below every low-rise rule: a riser too low to see
            # must be refused too, not only one too low to measure a tread against
            values = [min(LOWEST_RISE_M, limits.min_step_rise_m(cfg) - pad),
                      limits.max_step_rise_m(cfg) + pad]
        else:
            values = [max(0.01, limits.min_tread_m(cfg) - pad), limits.min_tread_m(cfg) + pad]
    metres = axis in METRE_AXES
    if tolerance is None:
        tol = 1.0 if integer else (0.001 if metres else (values[-1] - values[0]) / 100.0)
    else:
        tol = tolerance / 1000.0 if metres else tolerance
    width = values[-1] - values[0]
    if not (tol > 0 and math.isfinite(tol)) or (tol > width if integer else tol >= width):
        unit = "mm" if metres else "in the axis's unit"
        given = "the default" if tolerance is None else f"{tolerance:g}"
        raise SpecError(spec.source, None, f"--tolerance {given}: allowed: a number > 0 "
                        f"({unit}) less than the range searched, {values[0]:g} to "
                        f"{values[-1]:g}")
    if found is None or found.sampled or _range_of(found) is None:
        from stairbot.sweep.bisect import scan_values

        count = scan or max(DEFAULT_SCAN, 1 + math.ceil(
            (values[-1] - values[0]) / SCAN_STEP_M - 1e-9) if metres else DEFAULT_SCAN)
        values = scan_values(values[0], values[-1], count, integer, DIGITS)
    elif scan is not None:
        raise SpecError(spec.source, None, f"--scan: {axis} is a grid axis of this spec, "
                        "whose values are the scan; allowed: --scan only for a range the "
                        "spec does not list")
    return Target(axis, tuple(values), integer, tol, metres)


def points(spec: Spec, axis: str) -> list[Point]:
    """A search for each combination of the other grid axes' values (the
    axis itself at its first value: it is overridden).  Raises SpecError
    beyond MAX_POINTS."""
    grid = spec.grid_axes
    others = [a for a in grid if a.path != axis]
    count = math.prod(len(a.values) for a in others)
    if count > MAX_POINTS:
        sizes = " x ".join(f"{a.path} {len(a.values)}" for a in others if len(a.values) > 1)
        raise SpecError(spec.source, "axes", f"--boundary: the other grid axes make {count} "
                        f"points ({sizes}); allowed: at most {MAX_POINTS} (hold the others "
                        "at fewer values)")
    out = []
    for k in range(count):
        # the mixed-radix grid point with the axis's own index at 0
        idx: dict[str, int] = {}
        rest = k
        for a in reversed(others):
            rest, idx[a.path] = divmod(rest, len(a.values))
        point = 0
        for a in grid:
            point = point * len(a.values) + idx.get(a.path, 0)
        base = point * spec.samples_per_point
        held = {p: v for p, v in spec.axis_values(base).items() if p != axis}
        out.append(Point(base, held))
    return out


def _zone(spec: Spec, base: int, axis: str, value: float) -> str:
    return str(build_case(spec, base, (axis, value)).facts["zone"])


def published(spec: Spec, base: int, t: Target, fine: int = 200) -> list[Published]:
    """Where the zone changes along the axis at this point, with zero margins
    (the limit itself, not its band), to a micrometre of the axis."""
    bare = replace(spec, rules=Rules(0.0, 0.0, spec.rules.home_m))
    from stairbot.sweep.bisect import scan_values

    xs = scan_values(t.low, t.high, fine, t.integer)
    zs = [_zone(bare, base, t.axis, x) for x in xs]
    out = []
    for (a, za), (b, zb) in zip(zip(xs, zs, strict=True), list(zip(xs, zs, strict=True))[1:],
                                strict=False):
        if za == zb:
            continue
        lo, hi = a, b
        while not t.integer and hi - lo > 1e-6:
            mid = (lo + hi) / 2.0
            if _zone(bare, base, t.axis, mid) == za:
                lo = mid
            else:
                hi = mid
        value = hi if t.integer else round((lo + hi) / 2.0, 6)
        out.append(Published(value, za, zb, _name(spec, base, t.axis, value)))
    return out


def _name(spec: Spec, base: int, axis: str, value: float) -> str:
    """The robot's figure a published change equals, by name."""
    case = build_case(spec, base, (axis, value))
    cfg = config_of(case)
    figures: dict[str, float] = {}
    scen = case.scenario_text
    import tomllib

    stairs = tomllib.loads(scen).get("stairs", {})
    if axis == "stairs.rise":
        figures["max_step_rise_m"] = limits.max_step_rise_m(cfg)
        figures["min_step_rise_m"] = limits.min_step_rise_m(cfg)
        treads = {float(s["tread"]) for s in stairs.get("steps", [])} or (
            {float(stairs["tread"])} if "tread" in stairs else set())
        for tr in sorted(treads):
            figures[f"min_rise_for({tr:g})"] = cfg.min_rise_for(tr)
    elif axis == "stairs.tread":
        figures["min_tread_m"] = limits.min_tread_m(cfg)
        slope = cfg.min_rise_for(1.0) - cfg.min_rise_for(0.0)
        rises = {float(s["rise"]) for s in stairs.get("steps", [])} or (
            {float(stairs["rise"])} if "rise" in stairs else set())
        for r in sorted(rises):
            if slope > 0:  # the longest tread whose next riser r is high enough to measure
                figures[f"min_rise_for(tread) = {r:g}"] = (r - cfg.min_rise_for(0.0)) / slope
    named = [(abs(v - value), n) for n, v in figures.items() if abs(v - value) <= NAMED_WITHIN_M]
    return min(named)[1] if named else "the zone rules"
