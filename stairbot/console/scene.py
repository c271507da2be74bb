"""What the picture draws: the stairs outline and the robot's segments and
wheels in world coordinates (metres, x forward towards the stairs, y up).

:func:`scene_from_sim` reads whatever the simulation's ``scene()`` returns;
:func:`stairs_from_scenario` draws the stairs of a scenario for a wired robot,
whose pose the console cannot see.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from stairbot.scenario import Scenario

Point = tuple[float, float]


@dataclass(frozen=True)
class SceneView:
    """One frame of the picture.  ``segments`` run front (segment 1) to back
    (segment 3); each is a closed polygon.  ``wheels`` are (x, y, radius)."""

    stairs: tuple[Point, ...]
    segments: tuple[tuple[Point, ...], ...] = ()
    wheels: tuple[tuple[float, float, float], ...] = ()
    time_s: float | None = None

    def risers(self) -> list[float]:
        """The x of every riser (a rising vertical edge of the outline), in order."""
        xs = []
        for (ax, ay), (bx, by) in zip(self.stairs, self.stairs[1:], strict=False):
            if abs(ax - bx) < 1e-9 and by > ay + 1e-9:
                xs.append(ax)
        return xs

    def step_under(self, x: float) -> int:
        """0 on the floor before the first riser, n on the n-th tread."""
        return sum(1 for r in self.risers() if x >= r - 1e-6)

    def segment_steps(self) -> list[int]:
        """The step each segment stands over (by the segment's centre), front to back."""
        out = []
        for poly in self.segments:
            cx = sum(p[0] for p in poly) / len(poly)
            out.append(self.step_under(cx))
        return out

    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) over everything drawn."""
        pts: list[Point] = list(self.stairs)
        for poly in self.segments:
            pts.extend(poly)
        for x, y, r in self.wheels:
            pts.extend(((x - r, y - r), (x + r, y + r)))
        if not pts:
            return (0.0, 0.0, 1.0, 1.0)
        xs = [p[0] for p in pts]
        ys = [p[1] for p in pts]
        return (min(xs), min(ys), max(xs), max(ys))


def stairs_from_scenario(scenario: Scenario, robot_length: float) -> tuple[Point, ...]:
    """The side outline of a scenario's stairs: floor from behind the robot's
    start, each riser and tread, then a landing (or a wall too high to climb).
    The first riser stands at x = 0; the robot's front starts at -distance."""
    behind = scenario.start.distance + robot_length + 0.1
    pts: list[Point] = [(-behind, 0.0), (0.0, 0.0)]
    x = y = 0.0
    for step in scenario.steps:
        y += step.rise
        pts.append((x, y))
        x += step.tread
        pts.append((x, y))
    if not scenario.steps:
        pts[-1] = (1.5, 0.0)
    elif scenario.top == "wall":
        pts.append((x, y + 0.6))
    else:
        pts[-1] = (x + max(0.4, robot_length * 1.5), y)
    return tuple(pts)


def _point(value: Any) -> Point:
    if isinstance(value, Mapping):
        return (float(value["x"]), float(value["y"]))
    x, y = value[0], value[1]
    return (float(x), float(y))


def _points(values: Iterable[Any]) -> tuple[Point, ...]:
    return tuple(_point(v) for v in values)


def _get(obj: Any, *names: str) -> Any:
    for name in names:
        if isinstance(obj, Mapping) and name in obj:
            return obj[name]
        if hasattr(obj, name):
            return getattr(obj, name)
    return None


def _segment_polygon(seg: Any) -> tuple[Point, ...]:
    if isinstance(seg, Sequence) and seg and not isinstance(seg, str | bytes):
        first = seg[0]
        if isinstance(first, Sequence | Mapping):
            return _points(seg)
    corners = _get(seg, "corners", "polygon", "points", "outline", "vertices")
    if corners is not None:
        return _points(corners)
    raise ValueError(f"cannot read a segment from {type(seg).__name__}")


def _wheel(w: Any, default_radius: float) -> tuple[float, float, float]:
    if isinstance(w, Sequence) and not isinstance(w, str | bytes):
        if len(w) >= 3:
            return (float(w[0]), float(w[1]), float(w[2]))
        return (float(w[0]), float(w[1]), default_radius)
    centre = _get(w, "centre", "center", "position", "pos")
    radius = _get(w, "radius", "r")
    if centre is not None:
        cx, cy = _point(centre)
    else:
        cx, cy = float(_get(w, "x")), float(_get(w, "y"))
    return (cx, cy, float(radius) if radius is not None else default_radius)


def scene_from_sim(raw: Any) -> SceneView:
    """Adapt the simulation's ``scene()`` (a mapping or an object with
    ``stairs``, ``segments`` and ``wheels``) to a :class:`SceneView`.
    Raises ValueError when it cannot be read."""
    stairs = _get(raw, "stairs", "stairs_outline", "outline")
    segments = _get(raw, "segments", "bodies")
    wheels = _get(raw, "wheels")
    if stairs is None or segments is None:
        raise ValueError("the simulation's scene has no stairs or segments")
    time_s = _get(raw, "time_s", "time")
    radius = _get(raw, "wheel_radius")
    r = float(radius) if isinstance(radius, int | float) else 0.016
    return SceneView(
        stairs=_points(stairs),
        segments=tuple(_segment_polygon(s) for s in segments),
        wheels=tuple(_wheel(w, r) for w in (wheels or ())),
        time_s=float(time_s) if isinstance(time_s, int | float) else None,
    )
