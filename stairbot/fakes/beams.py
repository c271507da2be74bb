"""Cones of rays for the sensor models: what each ray of a sensor's cone meets.

The side view (the stairs' polyline) gives each ray's angle up or down; the
top view (:class:`~stairbot.fakes.plan.Plan`) turns a forward ray by the
robot's yaw plus the ray's angle across the cone and finds the riser or the
side wall it meets, from the mount where the robot's yaw alone puts it.  A
ray's incidence is the angle between it and the normal of the surface it
meets, in three dimensions: a riser's normal is along x, a tread's along y
(up), a side wall's across the flight.

Cost: a forward pair shares its side-view casts (``model.rays`` of them) and
adds ``rays * rays_across`` top-view evaluations per sensor; a downward sensor
casts ``model.rays`` rays (the cone across the robot is not modelled: the
treads are the same all across, and a yaw only moves the mounts, as for the
ideal sensors).
"""

from __future__ import annotations

import math

from stairbot.fakes.plan import Plan
from stairbot.fakes.sensor_model import Hit, SensorModel
from stairbot.fakes.world import World


def front_hits(world: World, plan: Plan, model: SensorModel, mount: tuple[float, float],
               pitch: float, forward: float, laterals: tuple[float, ...], reach: float
               ) -> list[list[Hit]]:
    """The hits of a forward sensor's cone for each of ``laterals`` (the mounts'
    offsets across the robot, + = left) on one segment: ``mount`` is the
    side-view position, ``pitch`` the segment's angle, ``forward`` the mount's
    distance ahead of segment 2's centre.  (Each ray's top view is
    :meth:`Plan.front_hit_at`, written out: a cone has a dozen rays per mount.)"""
    mx, my = mount
    tilt = model.tilt
    ups, acrosses, rays = model.cone_index
    profile = world.profile
    cos, sin = math.cos, math.sin
    ahead_i, behind_i = profile.starts(mx)
    cast, normals, inf = profile.first_from, profile.normals, math.inf
    # the side view, per angle up: how far ahead in x the ray meets the stairs
    # (None: nothing), the cos and sin of its angle, the normal met, its slant
    side_view: list[tuple[float | None, float, float, float, float, float]] = []
    for up in ups:
        theta = pitch + tilt + up
        c, s = cos(theta), sin(theta)
        x1 = mx + c * reach
        best, i = cast(mx, my, x1, my + s * reach, ahead_i, behind_i)
        slant = 1.0 / max(c, 1e-6)
        if best == inf:
            side_view.append((None, c, s, 0.0, 0.0, slant))
        else:
            nx, ny = normals[i]
            side_view.append(((mx + (x1 - mx) * best) - mx, c, s, nx, ny, slant))
    # the top view: the mounts turn with the robot's yaw only, a beam by its
    # angle across too; a mount sits forward*cos - lateral*sin ahead of segment
    # 2's centre (the side view's ray from ``forward`` ahead meets a riser
    # ``ahead`` less far) and y_m to the side
    half = plan.width / 2
    mount_c, mount_s = plan.yaw_trig()
    y_fwd, ahead = plan.y + forward * mount_s, forward * (1.0 - mount_c)
    turned = plan.turned(acrosses)
    out: list[list[Hit]] = [[] for _ in laterals]
    mounts = [(hits, y_fwd + lat * mount_c, lat * mount_s)
              for hits, lat in zip(out, laterals, strict=True)]
    if plan.left_wall or plan.right_wall:
        x_fwd = plan.x + forward * mount_c  # the mounts' top-view x, for walls over part of x
        _front_walls(plan, side_view, turned, rays, mounts, ahead,
                     [x_fwd - lat * mount_s for lat in laterals])
        return out
    for i_up, row in model.cone_rows:  # no side wall: a beam meets a riser or nothing
        hit_dx, c, s, nx, ny, slant = side_view[i_up]
        if hit_dx is None:
            continue
        riser_dx = hit_dx + ahead
        for i_across, weight in row:
            cos_psi, sin_psi = turned[i_across]
            if cos_psi <= 1e-9:
                continue
            on_stairs = abs(c * cos_psi * nx + s * ny)  # the cosine of its incidence
            for hits, y_m, side in mounts:
                dx = riser_dx + side
                if dx > 0.0 and abs(y_m + dx * sin_psi / cos_psi) <= half:
                    hits.append((dx / cos_psi * slant, on_stairs, weight))
    return out


def _front_walls(plan: Plan, side_view: list[tuple[float | None, float, float, float, float,
                                                   float]],
                 turned: list[tuple[float, float]], rays: tuple[tuple[int, int, float], ...],
                 mounts: list[tuple[list[Hit], float, float]], ahead: float,
                 xs: list[float]) -> None:
    """The top view of :func:`front_hits` beside side walls: each beam meets
    the nearer of the riser and the wall it turns towards, where that wall
    stands (``xs``: the mounts' top-view x)."""
    half, left_wall, right_wall = plan.width / 2, plan.left_wall, plan.right_wall
    wall_at, (left_all, right_all) = plan.wall_at, plan.whole_length()
    placed = [(hits, y_m, side, x_m) for (hits, y_m, side), x_m in zip(mounts, xs, strict=True)]
    for i_up, i_across, weight in rays:
        hit_dx, c, s, nx, ny, slant = side_view[i_up]
        cos_psi, sin_psi = turned[i_across]
        for hits, y_m, side, x_m in placed:
            best: float | None = None
            if hit_dx is not None and cos_psi > 1e-9:
                dx = hit_dx + ahead + side
                if dx > 0.0 and abs(y_m + dx * sin_psi / cos_psi) <= half:
                    best = dx / cos_psi * slant
            wall: float | None = None
            if sin_psi > 1e-9:
                if left_wall:
                    wall = max(0.0, (half - y_m) / sin_psi)
                    if not left_all and not wall_at(True, x_m + wall * cos_psi):
                        wall = None
            elif sin_psi < -1e-9 and right_wall:
                wall = max(0.0, (-half - y_m) / sin_psi)
                if not right_all and not wall_at(False, x_m + wall * cos_psi):
                    wall = None
            if wall is not None and (best is None or wall * slant < best):
                hits.append((wall * slant, abs(c * sin_psi), weight))
            elif best is not None:
                hits.append((best, abs(c * cos_psi * nx + s * ny), weight))


def down_hits(world: World, model: SensorModel, mount: tuple[float, float], pitch: float,
              reach: float) -> list[Hit]:
    """The hits of a downward sensor's fan at side-view position ``mount`` on a
    segment at angle ``pitch`` (+ tilt: the fan turned towards the front)."""
    return down_fans(world, model, (mount[0],), mount[1], pitch, reach)[0]


def down_fans(world: World, model: SensorModel, xs: tuple[float, ...], my: float,
              pitch: float, reach: float) -> list[list[Hit]]:
    """:func:`down_hits` for mounts at each of ``xs``, all at height ``my`` on
    one segment (a pair turned by a yaw): the rays' angles are shared."""
    tilt = model.tilt
    sin, cos, hypot = math.sin, math.cos, math.hypot
    # per ray: its direction, its extent along x and where it ends in y
    rays: list[tuple[float, float, float, float, float]] = []
    for up, _across, weight in model.fan:
        phi = pitch + tilt + up
        dx, dy = sin(phi), -cos(phi)
        rays.append((dx, dy, dx * reach, my + dy * reach, weight))
    profile = world.profile
    cast, normals, inf = profile.first_from, profile.normals, math.inf
    out: list[list[Hit]] = []
    for mx in xs:
        ahead_i, behind_i = profile.starts(mx)
        hits: list[Hit] = []
        for dx, dy, ex, y1, weight in rays:
            x1 = mx + ex
            best, i = cast(mx, my, x1, y1, ahead_i, behind_i)
            if best != inf:
                nx, ny = normals[i]
                hits.append((hypot((mx + (x1 - mx) * best) - mx, (my + (y1 - my) * best) - my),
                             abs(dx * nx + dy * ny), weight))
        out.append(hits)
    return out


def total_weight(cone: tuple[tuple[float, float, float], ...]) -> float:
    """The weight of every ray of a cone (the strength of a full beam)."""
    return sum(w for _, _, w in cone)
