"""Foxglove's well-known messages built from what the host knows: the
segments' frames, the stairs and the robot as a 3-D scene, the motors as
joint states, events as logs.  (The JSON channels' messages are plain dicts,
built in :mod:`stairbot.recording.channels`.)"""

from __future__ import annotations

import math
from collections.abc import Sequence

from foxglove.messages import (
    Color,
    CubePrimitive,
    CylinderPrimitive,
    FrameTransform,
    FrameTransforms,
    JointState,
    JointStates,
    Log,
    LogLevel,
    Pose,
    Quaternion,
    SceneEntity,
    SceneUpdate,
    Timestamp,
    Vector3,
)

from stairbot.events import Event, EventKind
from stairbot.hardware import LIFT_MOTORS, MotorId, Point, Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.recording.pose import (
    SEGMENT_FRAMES,
    WORLD_FRAME,
    SegmentPose,
    stair_blocks,
)

STAIRS_COLOUR = Color(r=0.62, g=0.6, b=0.56, a=1.0)
SEGMENT_COLOURS = (Color(r=0.85, g=0.37, b=0.0, a=0.9), Color(r=0.0, g=0.45, b=0.7, a=0.9),
                   Color(r=0.0, g=0.62, b=0.45, a=0.9))
WHEEL_COLOUR = Color(r=0.15, g=0.15, b=0.15, a=1.0)
_ABOUT_X_90 = Quaternion(x=math.sin(math.pi / 4), y=0.0, z=0.0, w=math.cos(math.pi / 4))
_IDENTITY = Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)

LEVELS: dict[EventKind, LogLevel] = {
    EventKind.PHASE: LogLevel.Info, EventKind.PAUSE: LogLevel.Warning,
    EventKind.RESUME: LogLevel.Info, EventKind.INFO: LogLevel.Info,
    EventKind.WARNING: LogLevel.Warning, EventKind.ERROR: LogLevel.Error,
    EventKind.LINK: LogLevel.Warning, EventKind.END: LogLevel.Info,
    EventKind.SUMMARY: LogLevel.Info,
}
"""A LINK event tells of trouble on the wire (retries, losses): a warning."""


def stamp(ns: int) -> Timestamp:
    return Timestamp(ns // 1_000_000_000, ns % 1_000_000_000)


def frame_transforms(poses: Sequence[SegmentPose], ns: int) -> FrameTransforms:
    """world -> segment1..3 at ``ns``."""
    ts = stamp(ns)
    out = []
    for frame, p in zip(SEGMENT_FRAMES, poses, strict=False):
        qx, qy, qz, qw = p.quaternion()
        out.append(FrameTransform(timestamp=ts, parent_frame_id=WORLD_FRAME,
                                  child_frame_id=frame,
                                  translation=Vector3(x=p.x, y=p.y, z=p.z),
                                  rotation=Quaternion(x=qx, y=qy, z=qz, w=qw)))
    return FrameTransforms(transforms=out)


def _box(cx: float, cy: float, cz: float, sx: float, sy: float, sz: float,
         colour: Color) -> CubePrimitive:
    return CubePrimitive(pose=Pose(position=Vector3(x=cx, y=cy, z=cz), orientation=_IDENTITY),
                         size=Vector3(x=sx, y=sy, z=sz), color=colour)


def scene(stairs: Sequence[Point], width: float, config: RobotConfig, ns: int) -> SceneUpdate:
    """The stairs (a block per tread, ``width`` across) in ``world``, and each
    segment, a box with its two wheel pairs, locked to its own frame (which
    the pose topic moves).  Entities live until replaced (lifetime 0)."""
    ts = stamp(ns)
    blocks = [_box((b.x0 + b.x1) / 2, 0.0, b.top / 2, b.x1 - b.x0, width, b.top, STAIRS_COLOUR)
              for b in stair_blocks(stairs)]
    entities = [SceneEntity(timestamp=ts, frame_id=WORLD_FRAME, id="stairs", cubes=blocks)]
    g = config.geometry
    lengths = (g.LENGTH_OF_FIRST_MODULE, g.LENGTH_OF_SECOND_MODULE, g.LENGTH_OF_THIRD_MODULE)
    d = 2 * g.wheel_radius
    for frame, length, colour in zip(SEGMENT_FRAMES, lengths, SEGMENT_COLOURS, strict=True):
        ax = length / 2 - g.wheel_inset
        wheels = [CylinderPrimitive(
            pose=Pose(position=Vector3(x=x, y=y, z=0.0), orientation=_ABOUT_X_90),
            size=Vector3(x=d, y=d, z=0.01), bottom_scale=1.0, top_scale=1.0,
            color=WHEEL_COLOUR)
            for x in (-ax, ax) for y in (-g.track_width / 2, g.track_width / 2)]
        body = _box(0.0, 0.0, g.segment_height / 2, length, g.track_width * 0.9,
                    g.segment_height, colour)
        entities.append(SceneEntity(timestamp=ts, frame_id=frame, id=frame, frame_locked=True,
                                    cubes=[body], cylinders=wheels))
    return SceneUpdate(entities=entities)


def joint_states(snap: Snapshot, config: RobotConfig, ns: int) -> JointStates:
    """The motors as joints: a wheel motor a revolute joint (rad, rad/s), a
    lift a prismatic one (its extension, m and m/s)."""
    per_turn = config.motors.lift_travel_per_turn
    joints = []
    for motor in MotorId:
        state = snap.motors.get(motor)
        if state is None:
            continue
        scale = per_turn if motor in LIFT_MOTORS else 2 * math.pi
        joints.append(JointState(name=motor.value, position=state.turns * scale,
                                 velocity=state.speed_tps * scale))
    return JointStates(timestamp=stamp(ns), joints=joints)


def log(event: Event, ns: int) -> Log:
    """An event as a log line: its kind as the name."""
    return Log(timestamp=stamp(ns), level=LEVELS.get(event.kind, LogLevel.Unknown),
               message=event.message, name=event.kind.value)


def phase_log(event: Event, ns: int) -> Log:
    """A phase change: the phase as the message, its flow as the name."""
    flow = event.data.get("flow")
    return Log(timestamp=stamp(ns), level=LogLevel.Info, message=event.phase or event.message,
               name=flow if isinstance(flow, str) else "")
