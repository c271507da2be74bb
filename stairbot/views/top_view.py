"""What the top view draws: the stairwell seen from above and the robot's
footprint on it, in flight 1's frame (metres; x along flight 1 from its first
riser, + towards the risers; y across it from its centre line, + left).

The stairwell is the simulation's (fakes/landing.py, ``Stairwell``): each
vertical face seen from above is a line -- flight 1's risers across the
flight, its side walls, a quarter-turn landing's far and side walls, the
second flight's risers and its wall -- under the same names, so the face a
wall contact names (``Truth.wall_contact``) can be shown.  It is built here
from the scenario alone (the core imports no simulation);
tests/console/test_top_view_geometry.py holds it equal to the simulation's.

The footprint is what the simulation checks against those faces: the three
segments end to end along the heading, segment 2's centre at the pose,
``track_width`` + :data:`FOOTPRINT_MARGIN` wide.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from stairbot.hardware import Point, Truth
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario

# The simulation's constants (fakes/stairs.py, fakes/landing.py), held equal by a test.
FLOOR_BEHIND = 30.0
"""Floor (and side walls) behind riser 1, m."""
LANDING = 3.0
"""A straight landing's length past the last tread; a second flight's top, m."""
OPEN_FLOOR = 30.0
"""Floor ahead when there are no stairs, m."""
FOOTPRINT_MARGIN = 0.02
"""The footprint is ``track_width`` plus this wide (the wheels' own width)."""

BEHIND_M = 0.5
"""Floor shown before riser 1 (the robot's start is added to it)."""
AHEAD_M = 0.6
"""The top shown past the last riser of a flight that ends on a straight landing."""
MARGIN_M = 0.15
"""Room around the stairwell when the whole of it is shown."""

RISER, RISER2, WALL = "riser", "riser2", "wall"


@dataclass(frozen=True, slots=True)
class PlanLine:
    """One vertical face seen from above, from ``a`` to ``b``; ``kind``:
    :data:`RISER` (flight 1's), :data:`RISER2` (the second flight's) or
    :data:`WALL`; ``name`` as the simulation names it."""

    a: Point
    b: Point
    kind: str
    name: str


@dataclass(frozen=True, slots=True)
class TopPlan:
    """The stairwell seen from above.  ``bounds`` (x0, y0, x1, y1): the part
    worth showing whole (walls run on behind and past it)."""

    lines: tuple[PlanLine, ...]
    bounds: tuple[float, float, float, float]
    across: float
    """How wide the stairwell is where the robot turns: flight 1's width, or a
    landing's depth where it is greater (a view following the robot shows it)."""
    landing: bool
    """A quarter-turn landing (the side view then switches frames on it)."""


@dataclass(frozen=True, slots=True)
class TopPose:
    """The robot seen from above, in flight 1's frame: segment 2's centre, the
    heading (degrees from straight up flight 1, + left), the flight whose
    frame the side view is in, and the first wall contact (None: none)."""

    x: float
    y: float
    yaw_deg: float
    flight: int = 1
    wall_contact: str | None = None


@dataclass(frozen=True, slots=True)
class RobotShape:
    """The footprint's size: the segments' lengths front to back, and its width."""

    lengths: tuple[float, float, float]
    width: float

    @classmethod
    def of(cls, config: RobotConfig) -> RobotShape:
        g = config.geometry
        return cls((g.LENGTH_OF_FIRST_MODULE, g.LENGTH_OF_SECOND_MODULE,
                    g.LENGTH_OF_THIRD_MODULE), g.track_width + FOOTPRINT_MARGIN)


def plan_of(scenario: Scenario) -> TopPlan:
    """The stairwell of ``scenario`` seen from above (see the module docstring)."""
    half, steps, landing = scenario.width / 2, scenario.steps, scenario.landing
    lines: list[PlanLine] = []

    def across(x: float, lo: float, hi: float, kind: str, name: str) -> None:
        lines.append(PlanLine((x, lo), (x, hi), kind, name))

    def along(y: float, lo: float, hi: float, kind: str, name: str) -> None:
        lines.append(PlanLine((lo, y), (hi, y), kind, name))

    x = 0.0
    for k in range(len(steps)):
        if k:
            x += steps[k - 1].tread
        across(x, -half, half, RISER, f"riser {k + 1}")
    x1 = x  # the last riser: the top edge
    far_x = x1 + (steps[-1].tread + AHEAD_M if steps else 1.0)  # what is shown of the top
    y0, y1 = -half, half
    if not steps:
        end = OPEN_FLOOR
    elif landing is not None:
        end = x1  # flight 1's side walls end at its top edge; the landing has its own
    elif scenario.top == "wall":
        end = far_x = x1 + steps[-1].tread
        across(end, -half, half, WALL, "the wall at the top")
    else:
        end = x1 + steps[-1].tread + LANDING
    for side, s in (("left", 1), ("right", -1)):
        if scenario.side_wall in (side, "both"):
            along(s * half, -FLOOR_BEHIND, end, WALL, f"flight 1's {side} wall")
    if landing is not None:
        s = 1 if landing.turn == "left" else -1
        other = "right" if s > 0 else "left"
        far_x = far = x1 + landing.depth
        second = landing.steps
        length2 = sum(step.tread for step in second) + LANDING if second else 0.0
        lo, hi = sorted((-s * half, s * (half + length2)))
        across(far, lo, hi, WALL, "the landing's far wall")
        along(-s * half, x1, far, WALL, f"the landing's {other} wall")
        if not second:
            along(s * half, x1, far, WALL,
                  f"the landing's {landing.turn} wall (no second flight)")
        else:
            y = half
            for k, step in enumerate(second):
                along(s * y, x1, far, RISER2, f"riser {k + 1} of flight 2")
                y += step.tread
            lo, hi = sorted((s * half, s * (half + length2)))
            across(x1, lo, hi, WALL, f"flight 2's {landing.turn} wall")
            # flight 2 shown to its last riser and a little of its top
            reach = s * (y - second[-1].tread + AHEAD_M)
            y0, y1 = min(y0, reach), max(y1, reach)
    start = scenario.start
    x0 = -(start.distance if start.on == "floor" else 0.0) - BEHIND_M
    y0, y1 = min(y0, start.lateral), max(y1, start.lateral)
    m = MARGIN_M
    wide = max(scenario.width, landing.depth if landing is not None else 0.0)
    return TopPlan(tuple(lines), (x0 - m, y0 - m, far_x + m, y1 + m), wide,
                   landing is not None)


def top_pose(truth: Truth) -> TopPose | None:
    """The robot seen from above, from what the simulation tells of itself;
    None: it does not tell its pose in flight 1's frame."""
    if truth.flight1_x_m is None or truth.flight1_y_m is None or truth.flight1_yaw_deg is None:
        return None
    return TopPose(truth.flight1_x_m, truth.flight1_y_m, truth.flight1_yaw_deg, truth.flight,
                   truth.wall_contact)


def footprint(pose: TopPose, shape: RobotShape) -> tuple[tuple[Point, ...], ...]:
    """Segments 1, 2 and 3 (front to back) seen from above, each a rectangle of
    four corners in flight 1's frame: end to end along the heading, segment 2
    centred on the pose (as the simulation's footprint check has them)."""
    l1, l2, l3 = shape.lengths
    hw = shape.width / 2
    stretches = ((l2 / 2, l2 / 2 + l1), (-l2 / 2, l2 / 2), (-(l2 / 2 + l3), -l2 / 2))
    return tuple(tuple(_place(pose, u, v) for u, v in ((lo, -hw), (hi, -hw), (hi, hw),
                                                        (lo, hw)))
                 for lo, hi in stretches)


def nose(pose: TopPose, shape: RobotShape, ahead: float) -> tuple[Point, Point]:
    """The middle of the robot's front face, and a point ``ahead`` metres
    beyond it along the heading: where it is going."""
    front = shape.lengths[1] / 2 + shape.lengths[0]
    return _place(pose, front, 0.0), _place(pose, front + ahead, 0.0)


def _place(pose: TopPose, u: float, v: float) -> Point:
    """The point ``u`` ahead of segment 2's centre and ``v`` to its left."""
    yaw = math.radians(pose.yaw_deg)
    c, s = math.cos(yaw), math.sin(yaw)
    return pose.x + u * c - v * s, pose.y + u * s + v * c


_CONTACT = re.compile(r"segment (\d+) against (.+) at (-?\d+(?:\.\d*)?) s")


def contact_parts(contact: str) -> tuple[int, str] | None:
    """The segment (1-3) and the face a wall contact names ("segment 2 against
    the landing's far wall at 41.20 s", fakes/sim.py); None: another wording."""
    met = _CONTACT.fullmatch(contact)
    return None if met is None else (int(met.group(1)), met.group(2))
