"""How close the simulated robot came to tipping, to a step's edge and to the
end of its lifts: the least of each over a run, from the physics' truth.

The side view decides it all (x forward, y up).  The robot **rests on** the
stairs where one of its wheels, or its chassis, lies within
``CONTACT_TOL_M`` of the stairs' surface: a tread, a nosing, or a riser (a
wheel held against a riser by its motor bears by friction).  (The physics'
own contacts come and go from one step to the next on a robot at rest: the
surfaces' distances are steadier.)

* **Stability**: how far the robot's centre of mass stands inside the
  horizontal span of the points where it rests on the stairs; negative
  outside it, at most 0 on a single point.
* **Edge**: how far the centre of a wheel that stands on a tread (rests on
  its flat straight below its centre) stands past the tread's nosing (its
  edge with a riser below), while no wheel drives, the wheels of the
  segment the lifts move left out: a wheel rolls over a nosing as the robot
  drives a segment onto or off a step, and passes it as a lift raises or
  lowers its segment, by design.  The floor before the first riser has no
  nosing.
* **Stroke**: the lift travel left at the more extended lift, after every
  control tick.

Stability and edge are looked at every ``contact_check_s`` of robot time
(:class:`~stairbot.fakes.world_params.WorldParams`, as the fall watch looks
up its contacts): a look costs several times a tick's other checks, and the
robot moves a few millimetres in that time.
"""

from __future__ import annotations

import math
from bisect import bisect_left
from collections.abc import Sequence

import pymunk

CONTACT_TOL_M = 0.005
"""How far from the surface a wheel or the chassis still counts as on it: a
gap the robot closes at once if it tips that way.  It rocks by a few
millimetres as a lift pushes (a wheel hops 2 mm off the floor and lands);
a segment the algorithm lifts for a turn or a step goes higher."""

Point = tuple[float, float]
Tread = tuple[float, float, float, float | None]  # x start, x end, y, nosing x (None: none)


def treads(outline: Sequence[Point]) -> list[Tread]:
    """The horizontal stretches of a stairs outline, in x order, each with
    its nosing: its start, where the outline comes up a riser onto it."""
    out: list[Tread] = []
    for k in range(len(outline) - 1):
        (ax, ay), (bx, by) = outline[k], outline[k + 1]
        if ay != by or bx <= ax:
            continue
        nosing = ax if k > 0 and outline[k - 1][1] < ay else None
        out.append((ax, bx, ay, nosing))
    return out


def nearest(px: float, py: float, a: Point, b: Point) -> tuple[float, float, float]:
    """The point of the segment a-b nearest to (px, py), and its squared distance."""
    (ax, ay), (bx, by) = a, b
    ex, ey = bx - ax, by - ay
    length2 = ex * ex + ey * ey
    t = 0.0 if length2 == 0.0 else max(0.0, min(1.0, ((px - ax) * ex + (py - ay) * ey)
                                                / length2))
    x, y = ax + t * ex, ay + t * ey
    return x, y, (px - x) ** 2 + (py - y) ** 2


Pose = tuple[float, float, float]  # x, y, angle


class MarginWatch:
    """The least stability, edge and stroke margins seen so far (None: never
    measured)."""

    def __init__(self, segments: Sequence[pymunk.Body], boxes: Sequence[pymunk.Poly],
                 wheels: Sequence[pymunk.Body], radius: float, surface: float,
                 stroke: float, every_s: float) -> None:
        """``segments``, ``boxes``: the robot's chassis bodies and shapes;
        ``wheels``: its wheels, each segment's (rear, front) in turn;
        ``radius``: a wheel's; ``surface``: the stairs' thickness (the
        physics segments' radius); ``stroke``: the lifts' travel each way;
        ``every_s``: how often stability and edge are looked at."""
        self.stability_m: float | None = None
        self.edge_m: float | None = None
        self.stroke_m: float | None = None
        self._vertices = [[(v.x, v.y) for v in box.get_vertices()] for box in boxes]
        self._radius, self._surface = radius, surface
        self._stroke = stroke
        self._every = every_s
        self._since = math.inf  # the first look is a whole one
        self._segment_mass = [(b.mass, b.center_of_gravity.x, b.center_of_gravity.y)
                              for b in segments]
        self._wheel_mass = [w.mass for w in wheels]
        self._total = sum((b.mass for b in segments), 0.0) + sum(self._wheel_mass, 0.0)
        self._outline: Sequence[Point] = ()
        self._treads: list[Tread] = []
        self._edges: list[tuple[Point, Point]] = []
        self._ends: list[float] = []

    def due(self, elapsed: float, lifts: Sequence[float]) -> bool:
        """``elapsed`` seconds after the last call: take the lifts' offsets
        now; True when stability and edge are to be looked at (:meth:`look`)."""
        stroke = self._stroke - max(abs(lifts[0]), abs(lifts[1]))
        if self.stroke_m is None or stroke < self.stroke_m:
            self.stroke_m = stroke
        self._since += elapsed
        if self._since < self._every - 1e-9:
            return False
        self._since = 0.0
        return True

    def look(self, outline: Sequence[Point], segments: Sequence[Pose],
             wheels: Sequence[Point], judged: tuple[int, ...]) -> None:
        """Where the robot rests on ``outline`` (the stairs now), its segments'
        origins at ``segments`` and its wheels' centres at ``wheels`` (in the
        order given at construction), and the edge margin of the wheels of
        the ``judged`` segments."""
        if outline is not self._outline:
            self._outline, self._treads = outline, treads(outline)
            # the outline runs forward in x: its edges in order, with where each ends
            self._edges = list(zip(outline, outline[1:], strict=False))
            self._ends = [b[0] for _a, b in self._edges]
        com = 0.0
        for (x, _y, angle), (m, gx, gy) in zip(segments, self._segment_mass, strict=True):
            com += m * (x + math.cos(angle) * gx - math.sin(angle) * gy)
        for (x, _y), m in zip(wheels, self._wheel_mass, strict=True):
            com += m * x
        com /= self._total
        xs = self._wheels_rest(wheels, judged)
        if not xs:
            return
        stability = min(com - min(xs), max(xs) - com)
        if self.stability_m is not None and stability >= self.stability_m:
            return  # the chassis resting too could only widen the span
        xs += self._chassis_rest(segments)
        stability = min(com - min(xs), max(xs) - com)
        if self.stability_m is None or stability < self.stability_m:
            self.stability_m = stability

    def _wheels_rest(self, wheels: Sequence[Point], judged: tuple[int, ...]) -> list[float]:
        """The x of each point where a wheel rests on the stairs; the edge
        margin of the ``judged`` segments' wheels on the way."""
        xs: list[float] = []
        edges, ends = self._edges, self._ends
        reach = self._radius + self._surface + CONTACT_TOL_M
        reach2 = reach * reach
        for i, (cx, cy) in enumerate(wheels):
            for a, b in edges[bisect_left(ends, cx - reach):]:
                if a[0] > cx + reach:
                    break
                x, y, d2 = nearest(cx, cy, a, b)
                if d2 <= reach2:
                    xs.append(x)
                    if i // 2 in judged:
                        self._edge(cx, y)
        return xs

    def _chassis_rest(self, segments: Sequence[Pose]) -> list[float]:
        """The x of each point where a chassis rests on the stairs: a corner of
        it near the stairs, or a corner of the stairs (a nosing) near its
        outline."""
        xs: list[float] = []
        edges, ends = self._edges, self._ends
        reach = self._surface + CONTACT_TOL_M
        reach2 = reach * reach
        for (x0, y0, angle), vertices in zip(segments, self._vertices, strict=True):
            cos_a, sin_a = math.cos(angle), math.sin(angle)
            corners = [(x0 + cos_a * vx - sin_a * vy, y0 + sin_a * vx + cos_a * vy)
                       for vx, vy in vertices]
            lo = min(c[0] for c in corners) - reach
            hi = max(c[0] for c in corners) + reach
            near = []
            for a, b in edges[bisect_left(ends, lo):]:
                if a[0] > hi:
                    break
                near.append((a, b))
            # no part of the stairs within reach of the chassis' lowest corner: none rests on it
            if not near or min(c[1] for c in corners) > max(
                    max(a[1], b[1]) for a, b in near) + reach:
                continue
            points = [a for a, _b in near if lo <= a[0] <= hi] + [near[-1][1]]
            for c, d in zip(corners, corners[1:] + corners[:1], strict=True):
                xs.extend(x for x, y in points if nearest(x, y, c, d)[2] <= reach2)
                xs.extend(x for x, _y, d2 in (nearest(c[0], c[1], a, b) for a, b in near)
                          if d2 <= reach2)
        return xs

    def _edge(self, cx: float, y: float) -> None:
        """A wheel centred at x ``cx`` rests on the stairs at height ``y``: if it
        stands on the flat of a tread with a nosing, how far past the nosing."""
        for _ax, bx, ty, nosing in self._treads:
            if nosing is not None and y == ty and nosing < cx <= bx:
                if self.edge_m is None or cx - nosing < self.edge_m:
                    self.edge_m = cx - nosing
                return
