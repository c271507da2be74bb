"""Reading a recording back (``stairbot plot``, the tests): an MCAP record,
whole or cut short, or a JSON-lines one.

An MCAP file is read record by record from its start (the ``mcap``
package's stream reader), not through its summary: a file whose writer was
killed (SIGKILL, a power cut) has no summary and may end inside a record,
and is read up to the last whole record before that (``complete`` False).
A JSON-lines record holds the events alone (phases, decisions, the end):
no telemetry.

Raises :class:`RecordingError` (bad input: exit 2) for a file that is
missing, not a regular file, empty, or neither kind of recording.
"""

from __future__ import annotations

import io
import json
import math
import os
import struct
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

from stairbot.errors import InputError, ReadFault
from stairbot.files import open_regular, shown
from stairbot.recording import topics
from stairbot.recording.pose import SEGMENT_FRAMES, DeadReckonedPose, SimulationPose, pitch_of

MCAP_MAGIC = b"\x89MCAP0\r\n"
POSE_TOPICS = (SimulationPose.topic, DeadReckonedPose.topic)


class RecordingError(InputError):
    """The file is not a recording that can be read (the message says why)."""


@dataclass
class Telemetry:
    """What a recording's ticks hold, as columns over time (robot seconds)."""

    time_s: list[float] = field(default_factory=list)
    """The sensors' ticks."""
    pitch_deg: list[float] = field(default_factory=list)
    """The IMU's pitch at those ticks (nan without an IMU reading)."""
    distance_m: dict[str, list[float]] = field(default_factory=dict)
    status: dict[str, list[str]] = field(default_factory=dict)
    motor_time_s: list[float] = field(default_factory=list)
    lift_m: dict[str, list[float]] = field(default_factory=dict)
    """The lifts' extensions (MTF, MTB) at the motors' ticks."""
    pose_topic: str | None = None
    pose_time_s: list[float] = field(default_factory=list)
    height_m: dict[str, list[float]] = field(default_factory=dict)
    """Each segment frame's height (its centre on the axle line)."""
    pose_pitch_deg: dict[str, list[float]] = field(default_factory=dict)


@dataclass
class Recording:
    path: str
    kind: str
    """"mcap" or "jsonl"."""
    events: list[dict[str, Any]]
    """Every event, as the JSON-lines record has it (time_s, kind, phase, message, data)."""
    telemetry: Telemetry
    counts: Counter[str]
    """Messages read per topic (MCAP)."""
    metadata: dict[str, dict[str, str]]
    attachments: dict[str, bytes]
    complete: bool
    """The file ended as a finished file does (False: cut short, read up to its end)."""


def read_recording(path: str | os.PathLike[str]) -> Recording:
    """Read the recording at ``path`` (see the module).  Raises RecordingError."""
    data = recording_bytes(path)
    name = shown(path)
    if data.startswith(MCAP_MAGIC):
        return _read_mcap(name, data)
    return read_jsonl(name, data)


class RecordingReadError(ReadFault):
    """The disk failed while a recording was read (exit 1, as every
    ReadFault).  One line naming the file."""


def recording_bytes(path: str | os.PathLike[str]) -> bytes:
    """The whole file at ``path``.  Raises RecordingError when it is not a
    regular file that can be opened, or is empty (blank); RecordingReadError
    when the read itself fails (a disk fault)."""
    fd = open_regular(path, RecordingError, "a recording")
    try:
        with os.fdopen(fd, "rb") as f:
            data = f.read()
    except OSError as exc:
        raise RecordingReadError(f"{shown(path)}: cannot read the recording: "
                                 f"{exc.strerror or exc}") from None
    if not data.strip():
        raise RecordingError(shown(path), None, "empty; allowed: an MCAP or JSON-lines "
                             "recording (stairbot run --record FILE.mcap or FILE.jsonl)")
    return data


def read_jsonl(name: str, data: bytes) -> Recording:
    """A JSON-lines record (``data``, named ``name`` in messages): its events,
    up to a last line cut short.  Raises RecordingError."""
    events: list[dict[str, Any]] = []
    lines = data.split(b"\n")
    for number, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            event = json.loads(line)
        except (ValueError, UnicodeDecodeError):
            if number == len(lines) and events:  # a last line cut short by a crash
                return Recording(name, "jsonl", events, Telemetry(), Counter(), {}, {}, False)
            raise RecordingError(name, f"line {number}", "not JSON; allowed: an MCAP file or "
                                 "JSON lines of stairbot events") from None
        if not (isinstance(event, dict) and isinstance(event.get("time_s"), int | float)
                and isinstance(event.get("kind"), str)):
            raise RecordingError(name, f"line {number}", "not a stairbot event (time_s, kind, "
                                 "message); allowed: an MCAP file or JSON lines of events")
        events.append(event)
    return Recording(name, "jsonl", events, Telemetry(), Counter(), {}, {}, True)


def _records(data: bytes) -> Iterator[Any]:
    """The file's records in order, up to where it ends or breaks off."""
    from mcap.stream_reader import StreamReader

    yield from StreamReader(io.BytesIO(data), record_size_limit=len(data)).records


@dataclass
class McapScan:
    """What a scan of an MCAP file found besides its messages."""

    metadata: dict[str, dict[str, str]]
    attachments: dict[str, bytes]
    counts: Counter[str]
    """Messages read per topic."""
    complete: bool
    """The file ended as a finished file does (False: cut short, read up to its end)."""


McapTake = Callable[[Any, Any, "Callable[[bytes], Any] | None", dict[str, dict[str, str]]],
                    None]
"""(channel, message, its protobuf decoder or None, the metadata so far):
one message, handed over in the file's order."""


def scan_mcap(name: str, data: bytes, take: McapTake) -> McapScan:
    """Hand every message of the stairbot MCAP recording ``data`` (named
    ``name`` in messages) to ``take``, in the file's order, up to where the
    file ends or breaks off (see the module).  Raises RecordingError for a
    file that is not a stairbot recording, or holds no message."""
    from mcap.exceptions import McapError
    from mcap.records import Attachment, Channel, Footer, Message, Metadata, Schema
    from mcap_protobuf.decoder import DecoderFactory

    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    decoders: dict[int, Callable[[bytes], Any]] = {}
    scan = McapScan({}, {}, Counter(), False)
    protobuf = DecoderFactory()
    try:
        for record in _records(data):
            if isinstance(record, Message):
                channel = channels.get(record.channel_id)
                if channel is None:
                    continue
                scan.counts[channel.topic] += 1
                take(channel, record, decoders.get(channel.id), scan.metadata)
            elif isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = record
                schema = schemas.get(record.schema_id)
                if record.message_encoding == "protobuf" and schema is not None:
                    decoder = protobuf.decoder_for(record.message_encoding, schema)
                    if decoder is not None:
                        decoders[record.id] = decoder
            elif isinstance(record, Metadata):
                scan.metadata[record.name] = dict(record.metadata)
            elif isinstance(record, Attachment):
                scan.attachments[record.name] = bytes(record.data)
            elif isinstance(record, Footer):
                scan.complete = True
    except (McapError, struct.error, ValueError, EOFError, _zstd_error()):
        scan.complete = False  # cut short: what came before stands
    if "stairbot" not in scan.metadata:
        raise RecordingError(name, None, "an MCAP file, but not a stairbot recording (no "
                             "'stairbot' metadata); allowed: stairbot run --record FILE.mcap")
    if not scan.counts:
        raise RecordingError(name, None, "a stairbot recording that holds no messages (the run "
                             "recorded nothing before it ended)")
    return scan


def _read_mcap(name: str, data: bytes) -> Recording:
    events: list[dict[str, Any]] = []
    tel = Telemetry()

    def take(channel: Any, message: Any, decoder: Callable[[bytes], Any] | None,
             metadata: dict[str, dict[str, str]]) -> None:
        _take(tel, events, metadata, channel, message, decoder)

    scan = scan_mcap(name, data, take)
    return Recording(name, "mcap", events, tel, scan.counts, scan.metadata, scan.attachments,
                     scan.complete)


def _zstd_error() -> type[Exception]:
    import zstandard

    error: type[Exception] = zstandard.ZstdError
    return error


def _take(tel: Telemetry, events: list[dict[str, Any]], metadata: dict[str, dict[str, str]],
          channel: Any, message: Any, decoder: Callable[[bytes], Any] | None) -> None:
    """File one message's values where the plot looks for them."""
    topic = channel.topic
    if topic == topics.SENSORS:
        m = json.loads(message.data)
        tel.time_s.append(m["time_s"])
        imu = m.get("imu")
        tel.pitch_deg.append(imu["pitch_deg"] if imu else math.nan)
        for name, reading in m.items():
            if isinstance(reading, dict) and "distance_m" in reading:
                tel.distance_m.setdefault(name, []).append(reading["distance_m"])
                tel.status.setdefault(name, []).append(reading["status"])
    elif topic == topics.MOTORS:
        m = json.loads(message.data)
        tel.motor_time_s.append(m["time_s"])
        for name, motor in m.items():
            if isinstance(motor, dict) and "extension_m" in motor:
                tel.lift_m.setdefault(name, []).append(motor["extension_m"])
    elif topic == topics.RECORD:
        events.append(json.loads(message.data))
    elif decoder is not None and topic in POSE_TOPICS:
        origin = int(metadata.get("stairbot", {}).get("time_origin_ns", "0"))
        tel.pose_topic = topic
        tel.pose_time_s.append((message.log_time - origin) / 1e9)
        for t in decoder(message.data).transforms:
            if t.child_frame_id in SEGMENT_FRAMES:
                tel.height_m.setdefault(t.child_frame_id, []).append(t.translation.z)
                q = (t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w)
                tel.pose_pitch_deg.setdefault(t.child_frame_id, []).append(
                    math.degrees(pitch_of(q)))
