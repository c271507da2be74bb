"""A dead-reckoned side view for a robot on a wire, whose pose the console
cannot see: where its segments should be, from the turn counters alone.

* x: the front starts ``start.distance`` before the first riser and moves by
  the mean wheel turns times the wheel circumference (every wheel motor is
  driven alike, and a wheel in the air spins with the rest);
* heights: MTF and MTB give segments 1 and 3 relative to segment 2, and the
  robot stands on whichever supports hold it highest: segment 2's axle is the
  lowest height at which no segment's wheels go below the stairs under them.

It is an estimate, drawn as one, not a measurement: slip, yaw and a robot
that has tipped are not in it.
"""

from __future__ import annotations

from collections.abc import Sequence

from stairbot.hardware import WHEEL_MOTORS, MotorId, Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.views.side_view import Point, SceneView


def ground_at(stairs: Sequence[Point], x: float) -> float:
    """Height of the stairs' surface at ``x``: the highest outline point at or
    before ``x`` on the polyline (treads are flat, risers vertical)."""
    height = stairs[0][1] if stairs else 0.0
    for px, py in stairs:
        if px <= x + 1e-9:
            height = py
        else:
            break
    return height


def dead_reckon(snap: Snapshot, stairs: Sequence[Point], config: RobotConfig,
                start_distance: float) -> SceneView:
    """The segments and wheels where the counters put them (see the module)."""
    g = config.geometry
    r = g.wheel_radius
    lengths = (g.LENGTH_OF_FIRST_MODULE, g.LENGTH_OF_SECOND_MODULE, g.LENGTH_OF_THIRD_MODULE)
    turns = [snap.turns(m) for m in WHEEL_MOTORS if m in snap.motors]
    travel = (sum(turns) / len(turns) if turns else 0.0) * config.wheel_circumference
    per_turn = config.motors.lift_travel_per_turn
    offsets = (snap.turns(MotorId.MTF) * per_turn if MotorId.MTF in snap.motors else 0.0, 0.0,
               snap.turns(MotorId.MTB) * per_turn if MotorId.MTB in snap.motors else 0.0)
    front = -start_distance + travel
    spans: list[tuple[float, float]] = []
    x = front
    for length in lengths:
        spans.append((x - length, x))
        x -= length
    wheel_xs = [(x0 + g.wheel_inset, x1 - g.wheel_inset) for x0, x1 in spans]
    # Segment 2's axle height: the lowest at which every wheel clears its ground.
    axle2 = max(max(ground_at(stairs, wx) for wx in pair) + r - off
                for pair, off in zip(wheel_xs, offsets, strict=True))
    segments: list[tuple[Point, ...]] = []
    wheels: list[tuple[float, float, float]] = []
    for (x0, x1), pair, off in zip(spans, wheel_xs, offsets, strict=True):
        axle = axle2 + off
        top = axle + g.segment_height
        segments.append(((x0, axle), (x1, axle), (x1, top), (x0, top)))
        wheels.extend((wx, axle, r) for wx in pair)
    return SceneView(stairs=tuple(stairs), segments=tuple(segments), wheels=tuple(wheels),
                     time_s=snap.time_s)
