"""A recording read back as a replay
(:class:`~stairbot.recording.replay_source.ReplaySource`), by
:func:`load_replay`.

An MCAP recording (``--record FILE.mcap``) gives one :class:`Tick` a control
cycle, rebuilt from the messages the cycle wrote at one log time:
``/robot/sensors`` and ``/robot/motors`` (the snapshot and the speeds
commanded), ``/robot/link`` (the link's figures) and the pose topic
(``/sim/true_pose`` or ``/robot/estimated_pose``: the segments' frames).
``/scene`` gives the stairs, ``/events/record`` the events.  A file cut
short (a run killed outright) is read up to where it ends
(:func:`stairbot.recording.read.scan_mcap`); a tick whose messages were not
all flushed keeps what was.  A JSON-lines record holds events alone: no tick.

Raises :class:`~stairbot.recording.read.RecordingError` (bad input: exit 2)
for a file that is missing, not a regular file, empty, named for one kind
and holding another or neither, and
:class:`~stairbot.recording.read.RecordingReadError` (exit 1) when the disk
fails the read.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import PurePath
from typing import Any

from stairbot.events import Event, EventKind
from stairbot.files import shown
from stairbot.hardware import (
    Imu,
    MotorId,
    MotorState,
    Point,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
)
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.schema import convert
from stairbot.inputs.sections import ConfigFile
from stairbot.recording import topics
from stairbot.recording.pose import SEGMENT_FRAMES, pitch_of
from stairbot.recording.read import (
    MCAP_MAGIC,
    POSE_TOPICS,
    RecordingError,
    read_jsonl,
    recording_bytes,
    scan_mcap,
)
from stairbot.recording.replay_source import PART_GAP_S, Part, ReplaySource, SegmentFrame, Tick

MCAP_SUFFIXES = (".mcap",)
JSONL_SUFFIXES = (".jsonl", ".ndjson")
ALLOWED = ("allowed: FILE.mcap (stairbot run --record FILE.mcap, or the console's w) "
           "or FILE.jsonl (a JSON-lines record)")
FLOOR_TOP_M = 0.0021
"""A block of the /scene stairs this low is the floor (drawn 2 mm thick)."""


def load_replay(path: str | os.PathLike[str]) -> ReplaySource:
    """The recording at ``path``, by its name: ``.mcap`` an MCAP recording,
    ``.jsonl`` (or ``.ndjson``) a JSON-lines record.  Raises RecordingError
    for bad input, RecordingReadError when the read fails."""
    name = shown(path)
    suffix = PurePath(os.fspath(path)).suffix.lower()
    if suffix not in MCAP_SUFFIXES + JSONL_SUFFIXES:
        what = f"suffix {suffix!r}" if suffix else "no suffix"
        raise RecordingError(name, None, f"not a recording's name ({what}); {ALLOWED}")
    data = recording_bytes(path)
    mcap = data.startswith(MCAP_MAGIC)
    if suffix in MCAP_SUFFIXES:
        if not mcap:
            raise RecordingError(name, None, f"named .mcap but not an MCAP file (it does not "
                                 f"begin as one); {ALLOWED}")
        return _Loader(name).load(data)
    if mcap:
        raise RecordingError(name, None, "an MCAP file named as JSON lines; name it .mcap")
    rec = read_jsonl(name, data)
    events = sorted((_event(e) for e in rec.events), key=lambda e: e.time_s)
    return ReplaySource(name, "jsonl", [], events, rec.complete, None)


def _event(raw: dict[str, Any], shift: Callable[[float], float] = float) -> Event:
    kind_text = str(raw.get("kind"))
    message = str(raw.get("message", ""))
    try:
        kind = EventKind(kind_text)
    except ValueError:  # a kind this version does not know: kept, named
        kind, message = EventKind.INFO, f"({kind_text}) {message}"
    data = raw.get("data")
    phase = raw.get("phase")
    return Event(shift(float(raw["time_s"])), kind, message,
                 phase if isinstance(phase, str) else None,
                 data if isinstance(data, dict) else {})


@dataclass
class _TickParts:
    """The messages of one tick as they come (one log time)."""

    time_s: float
    part: int
    sensors: dict[str, Any] | None = None
    motors: dict[str, Any] | None = None
    health: dict[str, float] = field(default_factory=dict)
    frames: tuple[SegmentFrame, ...] = ()


class _Loader:
    """An MCAP recording's messages, in file order, filed into ticks, events
    and parts.  A tick's messages come one after another (the writer holds a
    lock around them), so a tick is built as soon as the next one starts:
    its JSON is not kept."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.parts = [Part()]
        self.ticks: list[Tick] = []
        self.events: list[Event] = []
        self.unreadable: dict[str, int] = {}
        self._open: tuple[tuple[int, int], _TickParts] | None = None

    def load(self, data: bytes) -> ReplaySource:
        scan = scan_mcap(self.name, data, self.take)
        self._close()
        ticks = sorted(self.ticks, key=lambda t: t.time_s)  # stable: file order at a tie
        source = ReplaySource(self.name, "mcap", ticks,
                              sorted(self.events, key=lambda e: e.time_s), scan.complete, None,
                              self.parts)
        for topic, n in sorted(self.unreadable.items()):
            what = "tick" if topic == "ticks" else "message"
            source.notes.append(f"{n} unreadable {what}{'s' if n > 1 else ''}"
                                + ("" if topic == "ticks" else f" on {topic}") + " skipped")
        raw_config = scan.attachments.get("robot_config.json")
        if raw_config is not None:
            try:
                source.config = recorded_config(raw_config, self.name)
            except (RecordingError, ValueError, KeyError, TypeError, AttributeError) as exc:
                source.notes.append(f"the recording's robot config cannot be read ({exc})")
        else:
            source.notes.append("the recording holds no robot config")
        return source

    def take(self, channel: Any, message: Any, decoder: Callable[[bytes], Any] | None,
             metadata: dict[str, dict[str, str]]) -> None:
        topic = channel.topic
        try:
            self._take(topic, message, decoder, metadata)
        except (ValueError, KeyError, TypeError, AttributeError):
            self.unreadable[topic] = self.unreadable.get(topic, 0) + 1

    def _seen(self, robot_s: float) -> int:
        """A message of the current part at ``robot_s``: the part's index."""
        part = self.parts[-1]
        if part.first_t is None:
            part.first_t = part.last_t = robot_s
            if len(self.parts) == 1:
                part.start_s = robot_s  # the first part: the robot's own clock
        part.last_t = max(part.last_t, robot_s)
        return len(self.parts) - 1

    def _take(self, topic: str, message: Any, decoder: Callable[[bytes], Any] | None,
              metadata: dict[str, dict[str, str]]) -> None:
        """File one message where the replay looks for it."""
        if topic == topics.SCENE and decoder is not None:
            self._scene(decoder(message.data), metadata.get("robot", {}))
            return
        if topic == topics.RECORD:
            raw = json.loads(message.data)
            self._seen(float(raw["time_s"]))
            self.events.append(_event(raw, self.parts[-1].timeline))
            return
        if topic not in (topics.SENSORS, topics.MOTORS, topics.LINK, *POSE_TOPICS):
            return
        origin = int(metadata.get("stairbot", {}).get("time_origin_ns", "0"))
        robot_s = (message.log_time - origin) / 1e9
        index = self._seen(robot_s)
        key = (index, message.log_time)
        if self._open is None or self._open[0] != key:
            self._close()
            self._open = (key, _TickParts(robot_s, index))
        tick = self._open[1]
        if topic == topics.SENSORS:
            tick.sensors = json.loads(message.data)
            tick.time_s = float(tick.sensors["time_s"])
        elif topic == topics.MOTORS:
            tick.motors = json.loads(message.data)
            tick.time_s = float(tick.motors["time_s"])
        elif topic == topics.LINK:
            health = json.loads(message.data).get("health") or {}
            tick.health = {str(k): float(v) for k, v in health.items()
                           if isinstance(v, int | float)}
        elif decoder is not None:
            frames = {}
            for t in decoder(message.data).transforms:
                if t.child_frame_id in SEGMENT_FRAMES:
                    q = (t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w)
                    frames[t.child_frame_id] = SegmentFrame(t.translation.x, t.translation.z,
                                                            pitch_of(q))
            if all(f in frames for f in SEGMENT_FRAMES):
                tick.frames = tuple(frames[f] for f in SEGMENT_FRAMES)

    def _close(self) -> None:
        """Build the tick whose messages have all come."""
        if self._open is not None:
            parts = self._open[1]
            self._open = None
            if parts.sensors is None and parts.motors is None and not parts.frames:
                return  # nothing of it could be read (said as unreadable messages)
            try:
                self.ticks.append(_tick(parts, self.parts[parts.part]))
            except (ValueError, KeyError, TypeError, AttributeError):
                self.unreadable["ticks"] = self.unreadable.get("ticks", 0) + 1

    def _scene(self, update: Any, robot: dict[str, str]) -> None:
        """A robot opened (``watch``): its stairs, and a part of its own once
        the one before holds messages."""
        part = self.parts[-1]
        if part.first_t is not None:
            part = Part(start_s=part.end_s + PART_GAP_S)
            self.parts.append(part)
        part.url, part.scenario = robot.get("url", ""), robot.get("scenario", "")
        part.pose_topic = robot.get("pose_topic", "")
        for entity in update.entities:
            if entity.id == "stairs":
                part.stairs = _stairs([(c.pose.position.x - c.size.x / 2,
                                        c.pose.position.x + c.size.x / 2, c.size.z)
                                       for c in entity.cubes])


_MOTORS = tuple((m, m.value) for m in MotorId)  # an enum member's .value is slow
_SENSORS = tuple((s, s.value) for s in SensorId)
_STATUS = {s.value: s for s in SensorStatus}


def _tick(parts: _TickParts, part: Part) -> Tick:
    snap: Snapshot | None = None
    commanded: dict[MotorId, float] | None = None
    if parts.sensors is not None or parts.motors is not None:
        sensors = _readings(parts.sensors or {})
        motors: dict[MotorId, MotorState] = {}
        m = parts.motors or {}
        for motor, name in _MOTORS:
            entry = m.get(name)
            if isinstance(entry, dict):
                motors[motor] = MotorState(float(entry["turns"]), float(entry["speed_tps"]),
                                           entry.get("fault"))
        if m.get("sent"):
            commanded = {motor: float(entry["command_tps"]) for motor, name in _MOTORS
                         if isinstance(entry := m.get(name), dict)
                         and isinstance(entry.get("command_tps"), int | float)}
        snap = Snapshot(parts.time_s, sensors, motors, parts.health,
                        _imu(parts.sensors or {}))
    return Tick(part.timeline(parts.time_s), snap, commanded, parts.frames, parts.part)


def _readings(m: dict[str, Any]) -> dict[SensorId, SensorReading]:
    out = {}
    for sensor, name in _SENSORS:
        r = m.get(name)
        if isinstance(r, dict):
            out[sensor] = SensorReading(float(r["distance_m"]), _STATUS[r["status"]],
                                        float(r.get("age_s", 0.0)))
    return out


def _imu(m: dict[str, Any]) -> Imu | None:
    imu = m.get("imu")
    if not isinstance(imu, dict):
        return None
    return Imu(float(imu["pitch_deg"]), float(imu["roll_deg"]),
               float(imu.get("pitch_rate_dps", 0.0)), float(imu.get("roll_rate_dps", 0.0)),
               float(imu.get("age_s", 0.0)))


def recorded_config(raw: bytes, name: str) -> RobotConfig:
    """The robot config a recording attached (``robot_config.json``: the
    resolved config, as ``RobotConfig.to_dict`` writes it).  Raises
    RecordingError naming the field when it does not convert."""
    d = dict(json.loads(raw))
    source = str(d.pop("source", name))
    d.pop("derived", None)
    geometry = dict(d.get("geometry") or {})
    geometry.pop("LENGTH_OF_A_ROBOT", None)  # derived, written for the reader's sake
    d["geometry"] = geometry
    f = convert(d, ConfigFile, f"{name}: robot_config.json", RecordingError)
    return RobotConfig(source, f.geometry, f.masses, f.motors, f.sensors, f.algorithm,
                       f.safety)


def _stairs(blocks: list[tuple[float, float, float]]) -> tuple[Point, ...]:
    """The side outline from the /scene's stair blocks (each tread a block
    down to the floor): the treads' tops joined by vertical risers."""
    out: list[Point] = []
    for x0, x1, top in sorted(blocks):
        y = 0.0 if top <= FLOOR_TOP_M else top
        out.extend(((x0, y), (x1, y)))
    return tuple(out)

