"""A run's Foxglove channels (the topics of :mod:`stairbot.recording.topics`)
in one foxglove Context, and the messages logged on them: every sink added
to that context -- the MCAP record (:mod:`stairbot.recording.mcap_sink`),
the live WebSocket server (:mod:`stairbot.recording.live`) -- gets the same
channels and each message once.

One thing differs between the sinks: the 3-D scene (``/scene``) is logged
when a robot is opened, and a viewer that connects later would never see
the stairs and the segments.  So a live server gets a ``/scene`` channel of
its own (:meth:`RunChannels.serve_live`, metadata :data:`LIVE_KEY`) that
logs the scene again whenever a viewer subscribes to it
(:meth:`RunChannels.scene_again`), and the record's
``/scene`` channel keeps one scene per robot opened (the replay starts a
part of its own at each).  :meth:`RunChannels.for_record` and
:meth:`RunChannels.for_live` are the sinks' channel filters.

Thread-safe: hold :attr:`RunChannels.lock` around a sink's own writes
(the methods here take it themselves).
"""

from __future__ import annotations

import threading
import time
from typing import Any

import foxglove
from foxglove.channels import (
    FrameTransformsChannel,
    JointStatesChannel,
    LogChannel,
    SceneUpdateChannel,
)
from foxglove.messages import SceneUpdate

from stairbot.events import Event, EventKind
from stairbot.hardware import LIFT_MOTORS, MotorId, SensorId, Snapshot, Speeds
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario
from stairbot.recording import messages, topics
from stairbot.recording.pose import PoseSource

LIVE_KEY = "stairbot.sink"
"""Metadata of the live server's own ``/scene`` channel (value ``live``)."""


def _r(x: float) -> float:
    return round(x, 6)


class RunChannels:
    """The channels of one run (or one console) in :attr:`context`; log
    times are :attr:`origin_ns` plus the robot's clock."""

    def __init__(self, config: RobotConfig, *, origin_ns: int | None = None) -> None:
        self.config = config
        self.lock = threading.RLock()
        self.origin_ns = time.time_ns() if origin_ns is None else origin_ns
        self.context = ctx = foxglove.Context()
        self._pose: PoseSource | None = None
        self._pose_channel: FrameTransformsChannel | None = None
        self._scene_message: SceneUpdate | None = None
        self._live_scene: SceneUpdateChannel | None = None
        self._scene = SceneUpdateChannel(topics.SCENE, context=ctx)
        self._joints = JointStatesChannel(topics.JOINTS, context=ctx)
        self._motors = foxglove.Channel(topics.MOTORS, schema=topics.MOTORS_SCHEMA, context=ctx)
        self._sensors = foxglove.Channel(topics.SENSORS, schema=topics.SENSORS_SCHEMA,
                                         context=ctx)
        self._link = foxglove.Channel(topics.LINK, schema=topics.LINK_SCHEMA, context=ctx)
        self._events = LogChannel(topics.EVENTS, context=ctx)
        self._phase = LogChannel(topics.PHASE, context=ctx)
        self._record = foxglove.Channel(topics.RECORD, schema=topics.RECORD_SCHEMA, context=ctx)

    # -- the sinks' filters ------------------------------------------------------
    def for_record(self, channel: foxglove.ChannelDescriptor) -> bool:
        """The MCAP writer's channel filter: every channel but the live scene."""
        return channel.metadata.get(LIVE_KEY) != "live"

    def for_live(self, channel: foxglove.ChannelDescriptor) -> bool:
        """The live server's channel filter: every channel, its own scene
        for the record's."""
        return channel.id != self._scene.id()

    def serve_live(self) -> None:
        """Make the live server's ``/scene`` channel (before the server starts)."""
        with self.lock:
            if self._live_scene is None:
                self._live_scene = SceneUpdateChannel(topics.SCENE, context=self.context,
                                                      metadata={LIVE_KEY: "live"})

    def scene_again(self) -> None:
        """The last scene once more on the live scene channel: a viewer
        subscribed to it.  Called from the server's thread while a run may
        be logging, so without the lock: the SDK's channels are thread-safe,
        and the message is read once (a robot opened meanwhile logs its own)."""
        channel, message = self._live_scene, self._scene_message
        if channel is not None and message is not None:
            channel.log(message, log_time=self.origin_ns)

    def open_pose(self, topic: str, description: str) -> None:
        """The pose channel ``topic`` (kept while the topic stays).  A live
        server opens it before it starts (:mod:`stairbot.recording.live`):
        a viewer that subscribes at once to a channel advertised while it is
        connected may be told it does not exist (foxglove-sdk 0.30.3)."""
        with self.lock:
            if self._pose_channel is None or self._pose_channel.topic() != topic:
                self._pose_channel = FrameTransformsChannel(
                    topic, context=self.context, metadata={"source": description})

    # -- what a run logs -----------------------------------------------------------
    def watch(self, pose: PoseSource, scenario: Scenario) -> None:
        """Ticks from now on come from a robot on ``scenario``, posed by
        ``pose``: logs the 3-D scene and names the pose topic after what the
        pose is."""
        with self.lock:
            self._pose = pose
            self.open_pose(pose.topic, pose.description)
            ns = self.origin_ns
            self._scene_message = messages.scene(pose.stairs(), scenario.width, self.config, ns)
            self._scene.log(self._scene_message, log_time=ns)
            if self._live_scene is not None:
                self._live_scene.log(self._scene_message, log_time=ns)

    def write(self, event: Event) -> None:
        """Log ``event`` (as a log, a phase log for a phase change, and as
        the JSON-lines record's line)."""
        with self.lock:
            ns = self.ns(event.time_s)
            self._events.log(messages.log(event, ns), log_time=ns)
            if event.kind is EventKind.PHASE:
                self._phase.log(messages.phase_log(event, ns), log_time=ns)
            self._record.log(event.to_dict(), log_time=ns)

    def tick(self, snap: Snapshot, sent: Speeds | None) -> None:
        """Log one tick: ``snap`` as read, and ``sent``, the speeds commanded
        (None: nothing was sent, the emergency stop held every motor)."""
        with self.lock:
            ns = self.ns(snap.time_s)
            if self._pose is not None and self._pose_channel is not None:
                self._pose_channel.log(messages.frame_transforms(self._pose.poses(snap), ns),
                                       log_time=ns)
            self._joints.log(messages.joint_states(snap, self.config, ns), log_time=ns)
            self._motors.log(self._motors_message(snap, sent), log_time=ns)
            self._sensors.log(_sensors_message(snap), log_time=ns)
            self._link.log({"time_s": _r(snap.time_s), "health": dict(snap.health)},
                           log_time=ns)

    def ns(self, time_s: float) -> int:
        """The log time of robot time ``time_s``."""
        return self.origin_ns + max(0, round(time_s * 1e9))

    # -- inside ---------------------------------------------------------------------
    def _motors_message(self, snap: Snapshot, sent: Speeds | None) -> dict[str, Any]:
        per_turn = self.config.motors.lift_travel_per_turn
        out: dict[str, Any] = {"time_s": _r(snap.time_s), "sent": sent is not None}
        for motor in MotorId:
            state = snap.motors.get(motor)
            if state is None:
                continue
            entry: dict[str, Any] = {
                "turns": _r(state.turns), "speed_tps": _r(state.speed_tps),
                "command_tps": None if sent is None else _r(float(sent.get(motor, 0.0))),
                "fault": state.fault}
            if motor in LIFT_MOTORS:
                entry["extension_m"] = _r(state.turns * per_turn)
            out[motor.value] = entry
        return out


def _sensors_message(snap: Snapshot) -> dict[str, Any]:
    out: dict[str, Any] = {"time_s": _r(snap.time_s)}
    for sensor in SensorId:
        reading = snap.sensors.get(sensor)
        if reading is not None:
            out[sensor.value] = {"distance_m": _r(reading.distance_m),
                                 "status": reading.status.value, "age_s": _r(reading.age_s)}
    imu = snap.imu
    out["imu"] = None if imu is None else {
        "pitch_deg": _r(imu.pitch_deg), "roll_deg": _r(imu.roll_deg),
        "pitch_rate_dps": _r(imu.pitch_rate_dps), "roll_rate_dps": _r(imu.roll_rate_dps),
        "age_s": _r(imu.age_s)}
    return out
