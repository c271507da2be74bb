"""Where the segments are, in 3-D, for a recording: from the simulation's own
pose (``sim://``: the host is given it) or from the host's dead reckoning
(a robot on a wire, whose pose the host cannot see).

The side view (``stairbot.hardware.Scene``, the console's picture) has x
forward towards the risers and y up, riser 1 at x = 0.  In 3-D (Foxglove's
and ROS's convention) x stays forward, y is to the left and z up.  A
segment's frame has its origin at the segment's centre on its axle line
(where the simulation puts the segment's own origin), x along the segment,
z out of its top; the frame of a segment pitched nose up turns by minus the
pitch about y.

Pure Python: no Foxglove here (the MCAP writer turns these into messages).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

from stairbot.hardware import HasScene, Point, Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario
from stairbot.views.reckon import dead_reckon
from stairbot.views.side_view import stairs_from_scenario

SEGMENT_FRAMES = ("segment1", "segment2", "segment3")
"""The frames of segments 1, 2 and 3 (front to back), children of ``world``."""
WORLD_FRAME = "world"


@dataclass(frozen=True, slots=True)
class SegmentPose:
    """One segment's frame in the world: its origin (m) and its nose-up pitch
    and left yaw (rad)."""

    x: float
    y: float
    z: float
    pitch: float
    yaw: float

    def quaternion(self) -> tuple[float, float, float, float]:
        """The frame's rotation as (x, y, z, w): the yaw about z, then minus
        the pitch about the segment's own y (nose up turns x towards z)."""
        sz, cz = math.sin(self.yaw / 2), math.cos(self.yaw / 2)
        sy, cy = math.sin(-self.pitch / 2), math.cos(-self.pitch / 2)
        return (-sz * sy, cz * sy, sz * cy, cz * cy)


def pitch_of(quaternion: Sequence[float]) -> float:
    """The nose-up pitch (rad) of a frame rotated as :meth:`SegmentPose.quaternion`."""
    x, y, z, w = quaternion
    return -math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))


def side_pose(outline: Sequence[Point]) -> tuple[float, float, float]:
    """(x, y, pitch) of a segment outline's frame in the side view: the
    pitch of its most horizontal edge (valid below 45 degrees of pitch), the
    origin at the centre of its bottom (the axle line) in its own frame."""
    best = (0.0, 1.0, 0.0)  # (|dx|, dx, dy) of the chosen edge
    for (ax, ay), (bx, by) in zip(outline, (*outline[1:], outline[0]), strict=True):
        dx, dy = bx - ax, by - ay
        if abs(dx) > best[0]:
            best = (abs(dx), dx, dy) if dx > 0 else (abs(dx), -dx, -dy)
    pitch = math.atan2(best[2], best[1])
    c, s = math.cos(pitch), math.sin(pitch)
    along = [x * c + y * s for x, y in outline]  # the points in the segment's own axes
    up = [-x * s + y * c for x, y in outline]
    u, v = (min(along) + max(along)) / 2, min(up)
    return u * c - v * s, u * s + v * c, pitch


def segment_poses(outlines: Sequence[Sequence[Point]], yaw: float = 0.0,
                  lateral: float = 0.0) -> tuple[SegmentPose, ...]:
    """The segments' frames from their side-view outlines (front to back),
    the robot turned ``yaw`` (rad, + left) with segment 2's centre ``lateral``
    metres left of the flight's centre line (the simulation's top view)."""
    sides = [side_pose(o) for o in outlines]
    x2 = sides[1][0] if len(sides) > 1 else 0.0
    # the side view lays the robot along its axis: a segment (x - x2) ahead of
    # segment 2's centre stands that far along the heading, seen from above
    c, s = math.cos(yaw), math.sin(yaw)
    return tuple(SegmentPose(x2 + (x - x2) * c, lateral + (x - x2) * s, z, pitch, yaw)
                 for x, z, pitch in sides)


@dataclass(frozen=True, slots=True)
class Block:
    """A solid block of the stairs in the side view: from ``x0`` to ``x1``
    and from the floor (z = 0) up to ``top``."""

    x0: float
    x1: float
    top: float


WALL_THICKNESS = 0.05  # m: a wall at the top has no depth in the side outline
FLOOR_THICKNESS = 0.002


def stair_blocks(stairs: Sequence[Point]) -> list[Block]:
    """The stairs' outline (a polyline of treads and risers) as blocks: each
    tread a block down to the floor, a last rise with no tread after it (a
    wall) a block :data:`WALL_THICKNESS` deep."""
    blocks: list[Block] = []
    for i, ((ax, ay), (bx, by)) in enumerate(zip(stairs, stairs[1:], strict=False)):
        if abs(ay - by) < 1e-9 and bx > ax:
            blocks.append(Block(ax, bx, max(ay, FLOOR_THICKNESS)))
        elif abs(ax - bx) < 1e-9 and by > ay and i == len(stairs) - 2:
            blocks.append(Block(bx, bx + WALL_THICKNESS, by))
    return blocks


class PoseSource(Protocol):
    """Where a recording's pose comes from, and what it is called."""

    topic: str
    """The MCAP topic, named for what the pose is."""
    description: str

    def stairs(self) -> tuple[Point, ...]:
        """The stairs' side outline the pose stands on."""
        ...

    def poses(self, snap: Snapshot) -> tuple[SegmentPose, ...]:
        """The segments' frames at ``snap`` (front to back)."""
        ...


class SimulationPose:
    """The simulation's own pose of its segments (``sim://``): the truth."""

    topic = "/sim/true_pose"
    description = "the simulation's own pose of the segments (truth, not a measurement)"

    def __init__(self, sim: HasScene) -> None:
        self._sim = sim

    def stairs(self) -> tuple[Point, ...]:
        return self._sim.scene().stairs

    def poses(self, snap: Snapshot) -> tuple[SegmentPose, ...]:
        """In the first flight's frame, whichever frame the simulation's side
        view is in (a quarter-turn landing's second flight: its own), so
        that the recording's stairs (the first flight's) stay under it."""
        scene = self._sim.scene()
        poses = segment_poses(scene.segments, math.radians(scene.yaw_deg), scene.lateral_m)
        if scene.flight2 is None:
            return poses
        x_mid, sign = scene.flight2
        return tuple(SegmentPose(x_mid - sign * p.y, sign * p.x, p.z, p.pitch,
                                 p.yaw + sign * math.pi / 2) for p in poses)


class DeadReckonedPose:
    """The host's estimate for a robot on a wire: the segments where the wheel
    and lift turn counters put them on the scenario's stairs
    (:func:`stairbot.views.reckon.dead_reckon`).  Slip, yaw, the lateral
    position and a tipped robot are not in it."""

    topic = "/robot/estimated_pose"
    description = ("dead-reckoned from the wheel and lift turn counters on the scenario's "
                   "stairs (an estimate: no slip, yaw, lateral offset or tipping)")

    def __init__(self, config: RobotConfig, scenario: Scenario) -> None:
        self._config = config
        self._start = scenario.start.distance
        self._stairs = stairs_from_scenario(scenario, config.LENGTH_OF_A_ROBOT)

    def stairs(self) -> tuple[Point, ...]:
        return self._stairs

    def poses(self, snap: Snapshot) -> tuple[SegmentPose, ...]:
        view = dead_reckon(snap, self._stairs, self._config, self._start)
        return segment_poses(view.segments)


def pose_kind(url: str) -> type[SimulationPose] | type[DeadReckonedPose]:
    """Which pose a robot at ``url`` will have, before it is opened: the
    simulation's for ``sim://`` (it runs in this process), else the estimate."""
    return SimulationPose if url.split(":", 1)[0] == "sim" else DeadReckonedPose


def pose_source(sim: HasScene | None, config: RobotConfig, scenario: Scenario) -> PoseSource:
    """The simulation's pose when the host is given the simulation, else the
    dead-reckoned estimate."""
    if sim is not None:
        return SimulationPose(sim)
    return DeadReckonedPose(config, scenario)
