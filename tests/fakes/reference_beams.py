"""The ray casts and the beams' combination as they were before they were
made faster (stairbot/fakes/stairs.py, beams.py, sensor_model.combine on
d578101), kept frozen as the oracle the fast ones must agree with, bit for bit
(tests/fakes/test_casts_exact.py).  Not used by stairbot itself."""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right

from stairbot.fakes.plan import Plan
from stairbot.fakes.sensor_model import Hit, SensorModel

Geo = tuple[float, ...]


class Profile:
    """StairsProfile's casts: every candidate segment found by bisecting both ends."""

    def __init__(self, outline: list[tuple[float, float]], radius: float) -> None:
        segments = [(ax, ay, bx, by) for (ax, ay), (bx, by) in zip(outline, outline[1:],
                                                                   strict=False)]
        self.radius = radius
        self._xmin = [s[0] for s in segments]
        self._xmax = [s[2] for s in segments]
        self._geo: list[Geo | None] = []
        for ax, ay, bx, by in segments:
            ex, ey = bx - ax, by - ay
            length = math.hypot(ex, ey)
            if length == 0.0:
                self._geo.append(None)
                continue
            nx, ny = -ey / length, ex / length
            r_len = radius / length
            self._geo.append((ax, ay, ex, ey, length * length, nx, ny, -r_len, 1.0 + r_len,
                              ax + nx * radius, ay + ny * radius,
                              ax + -nx * radius, ay + -ny * radius))

    def ray_normal(self, x0: float, y0: float, x1: float, y1: float
                   ) -> tuple[float, float, float, float] | None:
        best, i = self.first(x0, y0, x1, y1)
        if best == math.inf:
            return None
        g = self._geo[i]
        assert g is not None
        return (x0 + (x1 - x0) * best, y0 + (y1 - y0) * best, g[5], g[6])

    def first(self, x0: float, y0: float, x1: float, y1: float) -> tuple[float, int]:
        r = self.radius
        lo, hi = (x0, x1) if x0 <= x1 else (x1, x0)
        first = bisect_left(self._xmax, lo - r)
        last = bisect_right(self._xmin, hi + r)
        if first >= last:
            return math.inf, -1
        dx, dy = x1 - x0, y1 - y0
        idx = range(first, last) if dx >= 0 else range(last - 1, first - 1, -1)
        inf = math.inf
        best, best_i = inf, -1
        for i in idx:
            g = self._geo[i]
            t = inf
            if g is not None:
                ax, ay, ex, ey, len2, nx, ny, u_lo, u_hi, px, py, mx, my = g
                side = (x0 - ax) * nx + (y0 - ay) * ny
                if side < 0.0:
                    side, px, py = -side, mx, my
                if side < r:
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
        return best, best_i


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
