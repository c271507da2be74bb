"""The stairs in the side view: one polyline, and rays cast against it.

Riser 1 stands at x = 0 on a floor at y = 0 that runs ``FLOOR_BEHIND`` metres
back.  Each step rises by its ``rise`` and runs its ``tread``.  After the last
riser the top is a ``LANDING`` metres long flat landing with nothing beyond
(``top = "landing"``) or, at the end of the last tread, a wall
``WALL_HEIGHT`` high (``top = "wall"``).  No steps: open floor far ahead.
With a quarter-turn landing (``scenario.landing``) the top is that landing,
``depth`` long from the last riser, and its far wall, ``WALL_HEIGHT`` high:
the side view of flight 1's frame (:mod:`stairbot.fakes.landing` has the
rest of the stairwell, and flight 2's frame).

The distance sensors cast their rays here rather than through pymunk's query
API: the outline is monotonic in x, so a ray meets its first surface among the
few segments its x-range spans, taken from its origin on (found by bisection,
once for all the rays of a cone from one mount), which costs a fraction of a
pymunk segment query.  Surfaces are offset by the physics segments' radius so
that the sensors see the same surface the wheels roll on.
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right

from stairbot.inputs.scenario import Scenario

FLOOR_BEHIND = 30.0  # floor length behind riser 1, m
LANDING = 3.0  # flat landing beyond the last tread, m
OPEN_FLOOR = 30.0  # floor ahead when there are no stairs, m
WALL_HEIGHT = 2.0

Point = tuple[float, float]


def stairs_outline(scenario: Scenario) -> list[Point]:
    """The stairs' surface as one polyline from far behind the start to the end."""
    pts: list[Point] = [(-FLOOR_BEHIND, 0.0)]
    if not scenario.steps:
        pts.append((OPEN_FLOOR, 0.0))
        return pts
    x = y = 0.0
    pts.append((x, y))
    last = len(scenario.steps) - 1
    landing = scenario.landing
    for i, step in enumerate(scenario.steps):
        y += step.rise
        pts.append((x, y))
        if i == last and landing is not None:
            # a quarter-turn landing: its far wall stands ``depth`` past the top edge
            # (the second flight leaves it sideways: fakes/landing.py)
            pts.append((x + landing.depth, y))
            pts.append((x + landing.depth, y + WALL_HEIGHT))
            break
        x += step.tread
        if i == last:
            if scenario.top == "wall":
                pts.append((x, y))
                pts.append((x, y + WALL_HEIGHT))
            else:
                pts.append((x + LANDING, y))
        else:
            pts.append((x, y))
    return pts


class StairsProfile:
    """Ray casts against an x-monotonic polyline whose surface is ``radius`` thick."""

    def __init__(self, outline: list[Point], radius: float = 0.0) -> None:
        self.segments: list[tuple[float, float, float, float]] = []
        for (ax, ay), (bx, by) in zip(outline, outline[1:], strict=False):
            if ax > bx:
                raise ValueError("the stairs outline must not run backwards in x")
            self.segments.append((ax, ay, bx, by))
        self.radius = radius
        self._xmin = [s[0] for s in self.segments]
        self._xmax = [s[2] for s in self.segments]
        # where first_from's walk stops: going forward, at a segment whose xmin is
        # beyond the ray's x-range; going back, at one whose xmax is before it,
        # which is one whose -xmax is beyond the ray's -x-range (the same test,
        # negated exactly).  One more entry, NaN (within no range), stops either
        # walk at its end: index n going forward, -1 going back.
        self._stops = (self._xmin + [math.nan], [-x for x in self._xmax] + [math.nan])
        # per segment, what every cast needs (see _Geo); a zero-length one meets nothing
        self._geo: list[_Geo] = []
        self.normals: list[tuple[float, float]] = []  # per segment (0, 0: zero length)
        for ax, ay, bx, by in self.segments:
            ex, ey = bx - ax, by - ay
            length = math.hypot(ex, ey)
            if length == 0.0:
                # no normal: inside the surface its parameter range is empty, and
                # a ray has no crossing with it (zero denominator)
                self._geo.append((ax, ay, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, ax, ay, ax, ay))
                self.normals.append((0.0, 0.0))
                continue
            nx, ny = -ey / length, ex / length
            self.normals.append((nx, ny))
            r_len = radius / length
            self._geo.append((ax, ay, ex, ey, length * length, nx, ny, -r_len, 1.0 + r_len,
                              ax + nx * radius, ay + ny * radius,
                              ax + -nx * radius, ay + -ny * radius))

    def ray(self, x0: float, y0: float, x1: float, y1: float) -> Point | None:
        """The first point of the surface on the segment (x0, y0) -> (x1, y1), or
        None when it meets nothing."""
        best, _ = self.first(x0, y0, x1, y1)
        if best == math.inf:
            return None
        return (x0 + (x1 - x0) * best, y0 + (y1 - y0) * best)

    def ray_normal(self, x0: float, y0: float, x1: float, y1: float
                   ) -> tuple[float, float, float, float] | None:
        """Like :meth:`ray`, with the unit normal of the segment it meets:
        (x, y, nx, ny), or None.  (At a rounded corner this is the normal of
        the segment hit, not of the rounding.)"""
        best, i = self.first(x0, y0, x1, y1)
        if best == math.inf:
            return None
        nx, ny = self.normals[i]
        return (x0 + (x1 - x0) * best, y0 + (y1 - y0) * best, nx, ny)

    def first(self, x0: float, y0: float, x1: float, y1: float) -> tuple[float, int]:
        """Ray parameter of the first surface met (inf: none) and its segment
        (its unit normal: ``normals[i]``)."""
        r = self.radius  # starts(x0), written out: every single-ray sensor casts here
        return self.first_from(x0, y0, x1, y1, bisect_left(self._xmax, x0 - r),
                               bisect_right(self._xmin, x0 + r) - 1)

    def starts(self, x0: float) -> tuple[int, int]:
        """The first segment a ray from ``x0`` can meet going forward (+x) and
        going back (the rays of a cone share them: see :meth:`first_from`)."""
        r = self.radius
        return bisect_left(self._xmax, x0 - r), bisect_right(self._xmin, x0 + r) - 1

    def first_from(self, x0: float, y0: float, x1: float, y1: float, ahead: int,
                   behind: int) -> tuple[float, int]:
        """:meth:`first`, given :meth:`starts` of ``x0``.

        The segments whose x-range (widened by ``radius``) overlaps the ray's
        are taken in the ray's direction along x, from the origin's end on
        (the far end is checked as it is reached: xmin and xmax are sorted).
        Per segment: the ray's parameter in [0, 1] where it crosses the
        segment's surface (the segment moved ``radius`` towards the ray's
        origin), 0 when the origin lies inside the surface beside the
        segment, none when it passes beside the segment's ends.  The first
        met ends the walk at the next segment that is not met nearer
        (x-monotonic: those after it lie further along the ray).  (One loop,
        no call per segment: every sensor casts here every tick.)"""
        r = self.radius
        dx, dy = x1 - x0, y1 - y0
        # the walk goes on while the next segment's bound is within lim (a NaN
        # ray ends it at once)
        if x0 <= x1:
            i, step, lim, bound = ahead, 1, x1 + r, self._stops[0]
        else:
            i, step, lim, bound = behind, -1, r - x1, self._stops[1]
        inf = math.inf
        best, best_i = inf, -1
        geo = self._geo
        while bound[i] <= lim:
            ax, ay, ex, ey, len2, nx, ny, u_lo, u_hi, px, py, mx, my = geo[i]
            t = inf
            side = (x0 - ax) * nx + (y0 - ay) * ny
            if side < 0.0:
                side, px, py = -side, mx, my
            if side < r:
                # inside the surface: touching it; beside the segment's end: not this one
                along = ((x0 - ax) * ex + (y0 - ay) * ey) / len2
                if u_lo <= along <= u_hi:
                    t = 0.0
            else:
                denom = dx * ey - dy * ex
                if denom != 0.0:
                    wx, wy = px - x0, py - y0
                    tt = (wx * ey - wy * ex) / denom
                    if 0.0 <= tt <= 1.0:
                        u = (wx * dy - wy * dx) / denom
                        if u_lo <= u <= u_hi:
                            t = tt
            if t < best:
                best, best_i = t, i
            elif best < inf and dx != 0.0:
                break
            i += step
        return best, best_i


_Geo = tuple[float, float, float, float, float, float, float, float,
             float, float, float, float, float]
"""A segment: start (ax, ay), direction (ex, ey), length squared, unit normal
(nx, ny), the range of the segment's parameter its surface covers (its ends
reach ``radius`` further), and the start moved ``radius`` along the normal
and against it."""
