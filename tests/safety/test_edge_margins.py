"""Where descent 1 leaves the robot at an ordinary edge: backed
edge_clearance_m past where the back pair crossed it, segment 3's front
wheels clear of the corner and segment 2's rear wheels still on the tread
(12 mm on, by the geometry, on the reference robot).

The reference robot's VL53L0X pair mixes its cone's returns by their
signal, and the tread 4 cm below outweighs the drop until nearly the whole
footprint has left it: the pair read the drop BACK_CLEARANCE x tan(12.5
deg), 8.9 mm, past the edge, and the crossing was placed there.  Backing
the clearance from there left segment 2's rear axle 1.8 mm on the tread
(median over 14 edges, 10 random flights; 0.2 mm past the edge at worst;
``python benchmarks/edge_margins.py``), on ir and heavy_middle (the same
pair) down to 2.4 mm past it; on the flight below 0.2 mm past it.  The
runs are on the pymunk robot, which knows the true edge."""

from __future__ import annotations

import math

from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.edge_measure import edge_doubt_m
from stairbot.control.algorithm.phases import Mode, Phase
from stairbot.control.robot_config import load_config
from stairbot.hardware import Snapshot
from stairbot.inputs.scenario import parse_scenario
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import run

REFERENCE = load_config("reference")
FLIGHT = """
[stairs]
steps = [{ rise = 0.123, tread = 0.393 }, { rise = 0.113, tread = 0.347 },
         { rise = 0.109, tread = 0.265 }]
[start]
distance = 0.3
yaw_deg = 8.0
[sensors]
seed = 8
"""


def test_segment_2s_rear_axle_stays_on_the_tread_at_an_ordinary_edge() -> None:
    """Where each backing up to an edge ends (as segment 3 is lowered):
    segment 2's rear wheels at least the crossing's doubt (edge_doubt_m)
    on the tread, on the nearer side (the robot may stand turned a little:
    its wheels across the track then stand at different distances from
    the edge), and segment 3's front wheels' front past the edge's
    corner, not on it (lowered there segment 3 stays up and the lift
    pitches the robot nose down)."""
    scenario = parse_scenario(FLIGHT, "edge_margins.toml")
    session = open_robot("sim://", REFERENCE, RobotOptions(world=scenario))
    world = session.robot.world  # type: ignore[attr-defined]
    plan = session.robot.plan  # type: ignore[attr-defined]
    g = REFERENCE.geometry
    radius = world.params.stairs_radius  # the stairs' surface: the outline this much thick
    edges, tops, x, y = [], [], 0.0, 0.0
    for step in scenario.steps:
        y += step.rise
        edges.append(x - radius)  # riser k's face, the edge of the tread on its top
        tops.append(y)
        x += step.tread
    phase = [""]
    ends: list[tuple[float, float]] = []  # (segment 2's rear axle on, segment 3's front clear)

    def along(wheel: int, segment: int, side: int) -> float:
        """Top-view x of one wheel of an axle (side -1 or +1 across the track)."""
        centre, yaw = world.pose(1)[0], plan.yaw
        wx = world.wheels[segment][wheel].position.x
        return centre + (wx - centre) * math.cos(yaw) + side * g.track_width / 2 * math.sin(yaw)

    def seen(ctl: Controller, _snap: Snapshot) -> None:
        now = ctl.phase.value
        if phase[0] == Phase.DESCENT_BACK_TO_EDGE.value and now == Phase.DESCENT_LOWER_THIRD.value:
            rear_y = world.wheels[1][0].position.y - g.wheel_radius
            level = min(range(len(tops)), key=lambda k: abs(tops[k] - rear_y))
            edge = edges[level]
            on = min(along(0, 1, s) for s in (-1, 1)) - edge
            clear = edge - (max(along(1, 2, s) for s in (-1, 1)) + g.wheel_radius)
            ends.append((on, clear))
        phase[0] = now

    try:
        result = run(session, REFERENCE, mode=Mode.for_start(scenario.start.on), on_tick=seen)
    finally:
        session.close()
    assert (result.outcome, result.steps_climbed, result.steps_descended) == (
        "completed", 3, 3), result.to_dict()
    assert len(ends) == 2, ends  # steps 2 and 1 (the top is left lowering segment 3)
    for on, clear in ends:
        assert on >= edge_doubt_m(REFERENCE), ends
        assert clear > 0.0, ends
