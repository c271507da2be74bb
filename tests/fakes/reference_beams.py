"""An oracle for the fast ray casts, cones and fans (stairbot/fakes/stairs.py,
beams.py) and the beams' combination (sensor_model.combine):
tests/fakes/test_casts_reference.py holds the fast ones to it.  Not used by
stairbot itself.  The cones' top view still goes through
:meth:`Plan.front_hit_at`, and :func:`combine` is the combination's rule
written out plainly; the side-view cast is independent.

The cast (:class:`Profile`) shares nothing with StairsProfile: no bisection,
no walk along x, no per-segment vectors.  The stairs' outline is made of
horizontal and vertical pieces only, so each piece's surface, ``radius``
thick, is worked out by hand as a box: the face towards the ray's origin,
``radius`` from the piece, reaching ``radius`` past its ends; every piece is
tried, and the nearest met wins (a tie goes to the piece met first along
the ray's direction in x, as the stairs are walked).  A ray that starts
inside a piece's surface meets it at once; one that starts in its slab but
beside its ends does not meet it at all.  The results agree with the fast
casts to rounding, not bit for bit, except where the fast cast's walk stops
short near a corner (test_casts_reference.py says where).
"""

from __future__ import annotations

import math

from stairbot.fakes.plan import Plan
from stairbot.fakes.sensor_model import Hit, SensorModel

TIE = 1e-12
"""Two pieces met within this much of the ray's length are met together."""


class Profile:
    """Ray casts against an outline of horizontal and vertical pieces, each
    piece's surface ``radius`` thick."""

    def __init__(self, outline: list[tuple[float, float]], radius: float) -> None:
        self.radius = radius
        self.pieces = list(zip(outline, outline[1:], strict=False))

    def meets(self, i: int, x0: float, y0: float, x1: float, y1: float) -> float | None:
        """Where (the ray's parameter in [0, 1]) the ray (x0, y0) -> (x1, y1)
        meets piece ``i``'s surface, or None."""
        r = self.radius
        (ax, ay), (bx, by) = self.pieces[i]
        if (ax, ay) == (bx, by):
            return None  # no piece: a repeated point
        if ay == by:  # a tread or a floor: its surface spans x in [lo, hi]
            lo, hi = min(ax, bx) - r, max(ax, bx) + r
            level, start, along, end, across = ay, y0, x0, y1, x1
        elif ax == bx:  # a riser or a wall: its surface spans y in [lo, hi]
            lo, hi = min(ay, by) - r, max(ay, by) + r
            level, start, along, end, across = ax, x0, y0, x1, y1
        else:
            raise AssertionError(f"not a horizontal or vertical piece: {self.pieces[i]}")
        gap = start - level  # from the piece to the origin, across it
        if abs(gap) < r:  # the origin is inside the surface's slab
            return 0.0 if lo <= along <= hi else None
        face = level + math.copysign(r, gap) if r > 0.0 else level
        if end == start:
            return None  # parallel to the piece
        t = (face - start) / (end - start)
        if not 0.0 <= t <= 1.0:
            return None
        at = along + t * (across - along)
        return t if lo <= at <= hi else None

    def first(self, x0: float, y0: float, x1: float, y1: float) -> tuple[float, int]:
        """The ray's parameter where it first meets the surface (inf: never),
        and the piece it meets there (-1: none)."""
        met = [(t, i) for i in range(len(self.pieces))
               if (t := self.meets(i, x0, y0, x1, y1)) is not None]
        if not met:
            return math.inf, -1
        nearest = min(t for t, _ in met)
        tied = [i for t, i in met if t - nearest <= TIE]
        return nearest, (min(tied) if x1 >= x0 else max(tied))

    def tied(self, x0: float, y0: float, x1: float, y1: float) -> list[int]:
        """Every piece the ray meets first (more than one: at a corner)."""
        best, _ = self.first(x0, y0, x1, y1)
        return [i for i in range(len(self.pieces))
                if (t := self.meets(i, x0, y0, x1, y1)) is not None and t - best <= TIE]

    def normal(self, i: int) -> tuple[float, float]:
        """Piece ``i``'s unit normal, to the left of its direction: up for a
        tread walked forward, back (-x) for a riser walked up."""
        (ax, ay), (bx, by) = self.pieces[i]
        if ay == by:
            return (0.0, 1.0 if bx > ax else -1.0)
        return (-1.0 if by > ay else 1.0, 0.0)

    def ray_normal(self, x0: float, y0: float, x1: float, y1: float
                   ) -> tuple[float, float, float, float] | None:
        """Where the ray first meets the surface, and the normal of the piece
        it meets: (x, y, nx, ny), or None."""
        best, i = self.first(x0, y0, x1, y1)
        if i < 0:
            return None
        nx, ny = self.normal(i)
        return (x0 + (x1 - x0) * best, y0 + (y1 - y0) * best, nx, ny)


def front_hits(profile: Profile, plan: Plan, model: SensorModel, mount: tuple[float, float],
               pitch: float, forward: float, laterals: tuple[float, ...], reach: float
               ) -> list[list[Hit]]:
    mx, my = mount
    tilt = math.radians(model.tilt_deg)
    out: list[list[Hit]] = [[] for _ in laterals]
    yaw = plan.yaw
    mount_c, mount_s = math.cos(yaw), math.sin(yaw)
    side_view: dict[float, tuple[float | None, float, float, float, float, float]] = {}
    turned: dict[float, tuple[float, float]] = {}
    for up, across, weight in model.cone:
        seen = side_view.get(up)
        if seen is None:
            theta = pitch + tilt + up
            c, s = math.cos(theta), math.sin(theta)
            hit = profile.ray_normal(mx, my, mx + c * reach, my + s * reach)
            slant = 1.0 / max(c, 1e-6)
            seen = ((None, c, s, 0.0, 0.0, slant) if hit is None
                    else (hit[0] - mx, c, s, hit[2], hit[3], slant))
            side_view[up] = seen
        hit_dx, c, s, nx, ny, slant = seen
        trig = turned.get(across)
        if trig is None:
            psi = yaw + across
            trig = turned[across] = (math.cos(psi), math.sin(psi))
        cos_psi, sin_psi = trig
        for i, lat in enumerate(laterals):
            got = plan.front_hit_at(forward, lat, hit_dx, slant, cos_psi, sin_psi, mount_c,
                                    mount_s)
            if got is None:
                continue
            d, on_wall = got
            cos_inc = abs(c * sin_psi) if on_wall else abs(c * cos_psi * nx + s * ny)
            out[i].append((d, cos_inc, weight))
    return out


def down_hits(profile: Profile, model: SensorModel, mount: tuple[float, float], pitch: float,
              reach: float) -> list[Hit]:
    mx, my = mount
    tilt = math.radians(model.tilt_deg)
    out: list[Hit] = []
    for up, _across, weight in model.fan:
        phi = pitch + tilt + up
        dx, dy = math.sin(phi), -math.cos(phi)
        hit = profile.ray_normal(mx, my, mx + dx * reach, my + dy * reach)
        if hit is None:
            continue
        x, y, nx, ny = hit
        out.append((math.hypot(x - mx, y - my), abs(dx * nx + dy * ny), weight))
    return out


def combine(model: SensorModel, hits: list[Hit], total_weight: float) -> float | None | str:
    """The distance combine() gives, or the name of its cause when it gives none."""
    if not hits:
        return "nothing"
    if model.max_incidence_deg is not None:
        min_cos = math.cos(math.radians(model.max_incidence_deg))
        hits = [h for h in hits if h[1] >= min_cos]
        if not hits:
            return "echo_lost"
    if model.weak_range is not None:
        strength = sum([g * c / (d * d) for d, c, g in hits if d > 0.0]) / total_weight
        if strength * model.weak_range * model.weak_range < 1.0:
            return "weak"
    if model.aggregate == "nearest" or len(hits) == 1:
        return min([h[0] for h in hits])
    num = den = 0.0
    for d, c, g in hits:
        w = g * c / (d * d) if d > 0.0 else g
        num += w * d
        den += w
    return num / den if den > 0.0 else min([h[0] for h in hits])
