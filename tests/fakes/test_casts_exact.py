"""The fast ray casts, cones and fans, and the beams' combination give what
they gave before they were made faster, bit for bit (the oracle:
tests/fakes/reference_beams.py), on random rays and poses."""

from __future__ import annotations

import math
import random
from dataclasses import replace

import reference_beams as ref
from reference_beams import Profile

from stairbot.config import load_config
from stairbot.fakes.beams import down_fans, down_hits, front_hits, total_weight
from stairbot.fakes.sensor_model import combine
from stairbot.fakes.sensor_presets import GP2Y0A21, HCSR04, PRESETS, VL53L0X, VL53L1X
from stairbot.fakes.sim import SimRobot
from stairbot.fakes.stairs import StairsProfile, stairs_outline
from stairbot.scenario import load_scenario

OUTLINES = [
    stairs_outline(load_scenario()),
    stairs_outline(load_scenario("wall_at_top")),
    # a zero-length segment (a repeated point) and a riser straight after a riser
    [(-1.0, 0.0), (0.0, 0.0), (0.0, 0.0), (0.0, 0.1), (0.0, 0.2), (0.3, 0.2), (0.3, 0.35),
     (1.5, 0.35)],
]


def test_casts_agree_with_the_reference() -> None:
    rng = random.Random(7)
    for outline in OUTLINES:
        top = max(y for _, y in outline)
        end = outline[-1][0]
        for radius in (0.0, 0.001, 0.02):
            fast, slow = StairsProfile(outline, radius), Profile(outline, radius)
            for n in range(4000):
                x0 = rng.uniform(-1.0, end + 1.0)
                y0 = rng.uniform(-0.05, top + 0.3)
                if n % 7 == 0:  # on a corner or a surface, where ties are
                    x0, y0 = rng.choice(outline)
                    y0 += rng.choice((0.0, radius, -radius))
                a, length = rng.uniform(-math.pi, math.pi), rng.uniform(0.0, 3.0)
                x1, y1 = x0 + length * math.cos(a), y0 + length * math.sin(a)
                if n % 11 == 0:
                    x1 = x0  # straight up or down
                assert fast.first(x0, y0, x1, y1) == slow.first(x0, y0, x1, y1)
                assert fast.ray_normal(x0, y0, x1, y1) == slow.ray_normal(x0, y0, x1, y1)


def _robot(scenario: str) -> SimRobot:
    return SimRobot(load_config("reference"), load_scenario(scenario))


def test_fans_agree_with_the_reference() -> None:
    rng = random.Random(8)
    for scenario in ("default", "wall_at_top"):
        robot = _robot(scenario)
        world = robot.world
        slow = Profile(world.outline, world.profile.radius)
        for model in (VL53L0X, replace(VL53L0X, tilt_deg=10.0, fov_deg=40.0), GP2Y0A21):
            for _ in range(600):
                xr = rng.uniform(-1.0, 2.5)
                xl = xr + rng.choice((0.0, rng.uniform(-0.05, 0.05)))
                my, pitch = rng.uniform(0.0, 1.2), rng.uniform(-0.6, 0.6)
                reach = rng.uniform(0.1, 2.5)
                want = [ref.down_hits(slow, model, (x, my), pitch, reach) for x in (xr, xl)]
                assert down_fans(world, model, (xr, xl), my, pitch, reach) == want
                assert down_hits(world, model, (xr, my), pitch, reach) == want[0]


def test_cones_agree_with_the_reference() -> None:
    rng = random.Random(9)
    robot = _robot("default")
    world, plan = robot.world, robot.plan
    slow = Profile(world.outline, world.profile.radius)
    models = (VL53L1X, replace(VL53L1X, tilt_deg=7.5, fov_deg=15.0), HCSR04, GP2Y0A21)
    for side_wall in ("none", "left", "right", "both"):
        plan.side_wall = side_wall
        for model in models:
            for _ in range(300):
                plan.width = rng.uniform(0.6, 1.2)
                plan.y = rng.uniform(-0.3, 0.3)
                plan.yaw = rng.uniform(-0.6, 0.6)
                mount = (rng.uniform(-1.5, 1.5), rng.uniform(0.0, 0.8))
                pitch, forward = rng.uniform(-0.5, 0.5), rng.uniform(0.0, 0.3)
                laterals = (-0.05, 0.05) if rng.random() < 0.8 else (rng.uniform(-0.1, 0.1),)
                reach = rng.uniform(0.2, 4.5)
                want = ref.front_hits(slow, plan, model, mount, pitch, forward, laterals, reach)
                got = front_hits(world, plan, model, mount, pitch, forward, laterals, reach)
                assert got == want


def test_combine_agrees_with_the_reference() -> None:
    rng = random.Random(10)
    for model in (*PRESETS.values(), replace(VL53L1X, weak_range=None),
                  replace(HCSR04, aggregate="weighted")):
        weight = total_weight(model.cone)
        for _ in range(2000):
            hits = [(rng.choice((0.0, rng.uniform(0.0, 4.0))), rng.uniform(0.0, 1.0),
                     rng.uniform(0.5, 1.0)) for _ in range(rng.randrange(0, 8))]
            distance, cause = combine(model, hits, weight)
            want = ref.combine(model, hits, weight)
            assert (distance if distance is not None else cause.value) == want
