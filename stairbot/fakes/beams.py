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
    distance ahead of segment 2's centre."""
    mx, my = mount
    tilt = math.radians(model.tilt_deg)
    out: list[list[Hit]] = [[] for _ in laterals]
    yaw = plan.yaw
    mount_c, mount_s = math.cos(yaw), math.sin(yaw)  # the mounts turn with the robot only
    cast = world.profile.ray_normal
    front_hit = plan.front_hit_at
    side_view: dict[float, tuple[float | None, float, float, float, float, float]] = {}
    turned: dict[float, tuple[float, float]] = {}  # across -> cos, sin of the beam's yaw
    for up, across, weight in model.cone:
        seen = side_view.get(up)
        if seen is None:
            theta = pitch + tilt + up
            c, s = math.cos(theta), math.sin(theta)
            hit = cast(mx, my, mx + c * reach, my + s * reach)
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
            got = front_hit(forward, lat, hit_dx, slant, cos_psi, sin_psi, mount_c, mount_s)
            if got is None:
                continue
            d, on_wall = got
            cos_inc = abs(c * sin_psi) if on_wall else abs(c * cos_psi * nx + s * ny)
            out[i].append((d, cos_inc, weight))
    return out


def down_hits(world: World, model: SensorModel, mount: tuple[float, float], pitch: float,
              reach: float) -> list[Hit]:
    """The hits of a downward sensor's fan at side-view position ``mount`` on a
    segment at angle ``pitch`` (+ tilt: the fan turned towards the front)."""
    mx, my = mount
    tilt = math.radians(model.tilt_deg)
    out: list[Hit] = []
    cast = world.profile.ray_normal
    for up, _across, weight in model.fan:
        phi = pitch + tilt + up
        dx, dy = math.sin(phi), -math.cos(phi)
        hit = cast(mx, my, mx + dx * reach, my + dy * reach)
        if hit is None:
            continue
        x, y, nx, ny = hit
        out.append((math.hypot(x - mx, y - my), abs(dx * nx + dy * ny), weight))
    return out


def total_weight(cone: tuple[tuple[float, float, float], ...]) -> float:
    """The weight of every ray of a cone (the strength of a full beam)."""
    return sum(w for _, _, w in cone)
