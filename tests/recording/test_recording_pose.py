"""The segments' frames for a recording: from side-view outlines (the
simulation's, the dead-reckoned ones) to 3-D poses, and the stairs as blocks."""

from __future__ import annotations

import math

import pytest

from stairbot.control.robot_config import load_config
from stairbot.hardware import BASE_SENSORS, MotorId, MotorState, SensorReading, Snapshot
from stairbot.inputs.scenario import load_scenario
from stairbot.recording.pose import (
    DeadReckonedPose,
    SegmentPose,
    pitch_of,
    segment_poses,
    side_pose,
    stair_blocks,
)
from stairbot.views.side_view import stairs_from_scenario


def rotate(q: tuple[float, float, float, float], v: tuple[float, float, float]
           ) -> tuple[float, float, float]:
    """v turned by the unit quaternion q = (x, y, z, w)."""
    x, y, z, w = q
    vx, vy, vz = v
    # t = 2 q_vec x v; v' = v + w t + q_vec x t
    tx, ty, tz = 2 * (y * vz - z * vy), 2 * (z * vx - x * vz), 2 * (x * vy - y * vx)
    return (vx + w * tx + y * tz - z * ty, vy + w * ty + z * tx - x * tz,
            vz + w * tz + x * ty - y * tx)


def turned(points: list[tuple[float, float]], angle: float, about: tuple[float, float]
           ) -> list[tuple[float, float]]:
    c, s = math.cos(angle), math.sin(angle)
    return [(about[0] + (x - about[0]) * c - (y - about[1]) * s,
             about[1] + (x - about[0]) * s + (y - about[1]) * c) for x, y in points]


@pytest.mark.parametrize("pitch_deg", [-30.0, -4.5, 0.0, 3.0, 40.0])
@pytest.mark.parametrize("yaw_deg", [-20.0, 0.0, 10.0])
def test_the_frame_turns_nose_up_and_left(pitch_deg: float, yaw_deg: float) -> None:
    p, y = math.radians(pitch_deg), math.radians(yaw_deg)
    q = SegmentPose(0.0, 0.0, 0.0, p, y).quaternion()
    assert math.fsum(c * c for c in q) == pytest.approx(1.0)
    forward = rotate(q, (1.0, 0.0, 0.0))
    assert forward == pytest.approx((math.cos(p) * math.cos(y), math.cos(p) * math.sin(y),
                                     math.sin(p)), abs=1e-12)
    assert rotate(q, (0.0, 0.0, 1.0))[2] == pytest.approx(math.cos(p))  # the top stays up
    assert pitch_of(q) == pytest.approx(p)


@pytest.mark.parametrize("pitch_deg", [-35.0, 0.0, 4.5, 30.0])
def test_a_segment_outline_gives_its_axle_centre_and_pitch(pitch_deg: float) -> None:
    # the simulation's chassis: chamfered at the bottom, from the axle line up
    half, ch, h = 0.0375, 0.004, 0.045
    local = [(-half + ch, 0.0), (half - ch, 0.0), (half, ch), (half, h), (-half, h), (-half, ch)]
    centre = (0.3, 0.2)
    outline = turned([(centre[0] + x, centre[1] + y) for x, y in local],
                     math.radians(pitch_deg), centre)
    x, y, pitch = side_pose(outline)
    assert (x, y) == pytest.approx(centre, abs=1e-9)
    assert math.degrees(pitch) == pytest.approx(pitch_deg)


def test_segments_off_the_centre_line_follow_the_yaw() -> None:
    box = [(-0.04, 0.0), (0.04, 0.0), (0.04, 0.05), (-0.04, 0.05)]
    outlines = [[(x + dx, y) for x, y in box] for dx in (0.1, 0.0, -0.1)]
    poses = segment_poses(outlines, yaw=math.radians(10), lateral=0.05)
    # 0.1 m ahead of segment 2's centre along the heading, seen from above
    c, s = math.cos(math.radians(10)), math.sin(math.radians(10))
    assert [p.x for p in poses] == pytest.approx([0.1 * c, 0.0, -0.1 * c])
    assert [p.y for p in poses] == pytest.approx([0.05 + 0.1 * s, 0.05, 0.05 - 0.1 * s])
    assert all(p.z == pytest.approx(0.0) and p.pitch == 0.0 for p in poses)


def test_the_stairs_as_blocks_and_a_wall_at_the_top() -> None:
    config = load_config(None)
    stairs = stairs_from_scenario(load_scenario(None), config.LENGTH_OF_A_ROBOT)
    blocks = stair_blocks(stairs)
    assert [round(b.top, 3) for b in blocks] == [0.002, 0.17, 0.34, 0.51, 0.68, 0.85]
    assert all(b.x1 > b.x0 for b in blocks) and blocks[1].x0 == 0.0  # riser 1 at x = 0
    wall = stair_blocks(stairs_from_scenario(load_scenario("wall_at_top"),
                                             config.LENGTH_OF_A_ROBOT))[-1]
    assert wall.x1 - wall.x0 == pytest.approx(0.05) and wall.top > 0.6


def test_the_dead_reckoned_pose_follows_the_counters() -> None:
    config = load_config(None)
    scenario = load_scenario(None)
    source = DeadReckonedPose(config, scenario)
    assert source.topic == "/robot/estimated_pose"

    def at(wheel_turns: float, lift_m: float) -> Snapshot:
        motors = {m: MotorState(turns=wheel_turns) for m in MotorId}
        motors[MotorId.MTF] = MotorState(turns=lift_m / config.motors.lift_travel_per_turn)
        motors[MotorId.MTB] = MotorState(turns=0.0)
        return Snapshot(0.0, {s: SensorReading(0.3) for s in BASE_SENSORS}, motors)

    start = source.poses(at(0.0, 0.0))
    r = config.geometry.wheel_radius
    assert [p.z for p in start] == pytest.approx([r, r, r])
    length = config.geometry.LENGTH_OF_FIRST_MODULE
    assert start[0].x == pytest.approx(-scenario.start.distance - length / 2)
    moved = source.poses(at(1.0, 0.05))  # one wheel turn on, segment 1 lifted 5 cm
    assert moved[1].x - start[1].x == pytest.approx(config.wheel_circumference)
    assert moved[0].z - moved[1].z == pytest.approx(0.05)
