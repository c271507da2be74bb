"""The run recorded as MCAP with the Foxglove SDK (``--record FILE.mcap``):
the robot's pose as frame transforms, a 3-D scene of the stairs and the
segments, the motors, the sensors, the link, the phases and events as logs,
and the robot config, the scenario and the CAN database as attachments.
The topics are in :mod:`stairbot.recording.topics`, the channels and their
messages in :mod:`stairbot.recording.channels` (which a live Foxglove
server, :mod:`stairbot.recording.live`, may share: the record is one sink
of them).

Crash safety: messages go into small zstd chunks, and the chunk in progress
is finished and written out every :data:`FLUSH_PERIOD_S` of wall time or
every :data:`FLUSH_TICKS` ticks, whichever comes first; the writer only
appends (:mod:`stairbot.recording.stream`).  A run killed outright (SIGKILL,
a power cut once the page cache is on disk) loses what came after the last
flush, and the file lacks its summary: :mod:`stairbot.recording.read` reads
such a file up to where it ends.

A write the disk refuses raises :class:`~stairbot.errors.OutputError` once
(the run loop then ends the run, the robot stopped); the record is silent
after.  Thread-safe: a console writes events from its UI thread and ticks
from the run thread.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import time
from collections.abc import Callable, Mapping
from importlib import resources
from typing import Any

import foxglove
import msgspec
from foxglove.mcap import MCAPCompression, MCAPWriteOptions

from stairbot import __version__
from stairbot.control.algorithm import limits
from stairbot.errors import OutputError
from stairbot.events import Event
from stairbot.files import shown
from stairbot.hardware import Snapshot, Speeds
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario
from stairbot.recording.channels import RunChannels
from stairbot.recording.pose import PoseSource
from stairbot.recording.stream import AppendStream

FLUSH_PERIOD_S = 0.5
"""Wall seconds between flushes at most (a run paced to the wall clock)."""
FLUSH_TICKS = 250
"""Ticks between flushes at most (5 s of robot time at the 20 ms tick: a
simulation running faster than the wall clock)."""
CHUNK_BYTES = 256 * 1024
"""A chunk's uncompressed size at most, between flushes."""

WHAT = "the record"

# The SDK warns on its logger for every message it could not write; this
# module reports the first refused write itself, as one line.
logging.getLogger("foxglove.log_sink_set").setLevel(logging.ERROR)


def _options() -> MCAPWriteOptions:
    # compression_threads=0: compress on the writing thread, never one per CPU
    return MCAPWriteOptions(compression=MCAPCompression.Zstd, chunk_size=CHUNK_BYTES,
                            disable_seeking=True, compression_threads=0,
                            profile="stairbot")


class McapRecord:
    """An MCAP record at ``path`` (truncated first) of ``channels`` (a
    :class:`~stairbot.recording.channels.RunChannels` of the record's own
    when None: given, a live server on them sees the same messages).
    Raises InputError when the file cannot be opened, OutputError when its
    start (header, attachments) cannot be written.  :meth:`watch` says which
    robot the ticks come from; :meth:`write` takes events, :meth:`tick`
    ticks: each logs on the channels, to every sink of theirs."""

    def __init__(self, path: str | os.PathLike[str], config: RobotConfig, *,
                 wall: Callable[[], float] = time.monotonic,
                 origin_ns: int | None = None,
                 channels: RunChannels | None = None) -> None:
        self.channels = RunChannels(config, origin_ns=origin_ns) if channels is None \
            else channels
        self._stream = AppendStream(path, WHAT)
        self.path = self._stream.path
        self._config = config
        self._wall = wall
        self._lock = self.channels.lock
        self.origin_ns = self.channels.origin_ns
        self._raised = False
        self._closed = False
        self._ticks = self._unflushed = 0
        self._last_flush = wall()
        try:
            self._writer = foxglove.open_mcap(self._stream, context=self.channels.context,
                                              channel_filter=self.channels.for_record,
                                              writer_options=_options())
        except RuntimeError as exc:
            self._stream.close()
            raise self._stream.failed or OutputError(shown(self.path), WHAT, str(exc)) from None
        try:
            with self._lock:
                self._call(self._writer.write_metadata, "stairbot", {
                    "version": __version__, "time_origin_ns": str(self.origin_ns),
                    "time": "log time = time_origin_ns + the robot's clock (time_s)",
                    "config": config.source})
                self._attach("robot_config.json", "application/json",
                             json.dumps(limits.config_dict(config), indent=1).encode())
                dbc = resources.files("stairbot").joinpath("drivers/stairbot.dbc")
                self._attach("stairbot.dbc", "text/plain", dbc.read_bytes())
                self._flush()
        except BaseException:
            self.close()
            raise

    # -- what a run calls -----------------------------------------------------------
    @property
    def failed(self) -> OutputError | None:
        """Why the disk refused a write, or None."""
        return self._stream.failed

    def watch(self, pose: PoseSource, scenario: Scenario, robot: str) -> None:
        """Ticks from now on come from ``robot`` on ``scenario``, posed by
        ``pose``: attaches the scenario, writes the 3-D scene, and names the
        pose topic after what the pose is."""
        with self._lock:
            if self._silent():
                return
            self._call(self._writer.write_metadata, "robot", {
                "url": robot, "scenario": scenario.name, "scenario_source": scenario.source,
                "pose_topic": pose.topic, "pose": pose.description})
            self._attach("scenario.json", "application/json",
                         json.dumps(_scenario_dict(scenario), indent=1).encode())
            self._call(self.channels.watch, pose, scenario)
            self._flush()

    def write(self, event: Event) -> None:
        """Record ``event`` (as a log, a phase log for a phase change, and as
        the JSON-lines record's line).  OutputError when the disk refuses it."""
        with self._lock:
            if self._silent():
                return
            self._call(self.channels.write, event)
            if self._wall() - self._last_flush >= FLUSH_PERIOD_S:
                self._flush()

    def tick(self, snap: Snapshot, sent: Speeds | None) -> None:
        """Record one tick: ``snap`` as read, and ``sent``, the speeds
        commanded (None: nothing was sent, the emergency stop held every
        motor).  OutputError when the disk refuses it."""
        with self._lock:
            if self._silent():
                return
            self._call(self.channels.tick, snap, sent)
            self._ticks += 1
            self._unflushed += 1
            if (self._unflushed >= FLUSH_TICKS
                    or self._wall() - self._last_flush >= FLUSH_PERIOD_S):
                self._flush()

    @property
    def ticks(self) -> int:
        """Ticks recorded so far."""
        return self._ticks

    def flush(self) -> None:
        """Write out the chunk in progress now."""
        with self._lock:
            if not self._silent():
                self._flush()

    def close(self) -> None:
        """Finish the file (its summary and footer).  Never raises once a
        write was refused (the file keeps what was written before); raises
        OutputError when the disk refuses the end of a file that was whole."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            try:
                if self._stream.failed is None:
                    self._call(self._writer.close)
                else:
                    with contextlib.suppress(RuntimeError, OutputError):
                        self._writer.close()
            finally:
                self._stream.close()

    # -- inside ---------------------------------------------------------------------
    def _silent(self) -> bool:
        return self._closed or self._stream.failed is not None

    def _call(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> None:
        """Call the SDK; a write the disk refused (which the SDK logs, or
        raises as RuntimeError) raises OutputError here, once."""
        try:
            fn(*args, **kwargs)
        except RuntimeError as exc:
            if self._stream.failed is None:  # not the disk: say what the SDK said
                raise OutputError(shown(self.path), WHAT, str(exc)) from None
        failed = self._stream.failed
        if failed is not None and not self._raised:
            self._raised = True
            raise failed

    def _attach(self, name: str, media_type: str, data: bytes) -> None:
        self._call(self._writer.attach, log_time=self.origin_ns, create_time=self.origin_ns,
                   name=name, media_type=media_type, data=data)

    def _flush(self) -> None:
        self._call(self._writer.flush)
        self._unflushed = 0
        self._last_flush = self._wall()


def _scenario_dict(scenario: Scenario) -> Mapping[str, Any]:
    out: Mapping[str, Any] = msgspec.to_builtins(scenario)
    return out
