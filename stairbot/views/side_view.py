"""What the picture draws: the stairs outline and the robot's segments and
wheels in world coordinates (metres, x forward towards the stairs, y up).

:func:`scene_view` draws the simulation's :class:`~stairbot.hardware.Scene`
(its ``scene()``, HasScene); :func:`stairs_from_scenario` draws the stairs of
a scenario for a wired robot, whose pose the console cannot see.
"""

from __future__ import annotations

from dataclasses import dataclass

from stairbot.hardware import Point, Scene
from stairbot.inputs.scenario import Scenario


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
    The first riser stands at x = 0; the robot's front starts at -distance,
    or, on the top (``start.on = "top"``), its rear distance past the top
    edge, and it ends on the floor behind the first riser."""
    top = scenario.start.on == "top"
    behind = 2 * robot_length + 0.4 if top else scenario.start.distance + robot_length + 0.1
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
        room = max(0.4, robot_length * 1.5)
        if top:  # past the top edge: the start, the robot, and a little
            room = max(room, scenario.start.distance + robot_length + 0.1
                       - scenario.steps[-1].tread)
        pts[-1] = (x + room, y)
    return tuple(pts)


def scene_view(scene: Scene) -> SceneView:
    """The picture of a simulation's scene: its outlines as they are, each
    wheel with the scene's wheel radius."""
    r = scene.wheel_radius
    return SceneView(
        stairs=scene.stairs,
        segments=scene.segments,
        wheels=tuple((x, y, r) for x, y in scene.wheels),
        time_s=scene.time_s,
    )
