"""A run's record, its kind chosen by the file's name: MCAP for ``.mcap``
(:mod:`stairbot.recording.mcap_sink`, imported only then: the Foxglove SDK
loads for MCAP alone), JSON lines -- one event a line, what ``--record``
has always written -- for any other name."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from stairbot.errors import OutputError
from stairbot.events import Event
from stairbot.files import LineFile
from stairbot.hardware import Snapshot, Speeds
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario

if TYPE_CHECKING:  # the pose module draws on the console's side view
    from stairbot.recording.channels import RunChannels
    from stairbot.recording.pose import PoseSource

MCAP_SUFFIX = ".mcap"


class EventRecord(Protocol):
    """Where a run's events go.  ``write`` raises OutputError the first time
    the disk refuses one (the run then stops); the record is silent after,
    and ``failed`` says why."""

    path: Path

    @property
    def failed(self) -> OutputError | None:
        ...

    def write(self, event: Event) -> None:
        ...

    def close(self) -> None:
        ...


@runtime_checkable
class RecordsTicks(Protocol):
    """A record that keeps every tick too (MCAP), and the robot's pose."""

    def watch(self, pose: PoseSource, scenario: Scenario, robot: str) -> None:
        """Ticks from now on come from ``robot`` on ``scenario``."""
        ...

    def tick(self, snap: Snapshot, sent: Speeds | None) -> None:
        """One tick: the snapshot read and the speeds sent (None: none were)."""
        ...


class JsonLinesRecord:
    """The events, one JSON object a line (``Event.to_json``), each line
    whole (:class:`~stairbot.files.LineFile`).  Raises InputError when the
    file cannot be opened."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self._file = LineFile(path, "the record")
        self.path = self._file.path

    @property
    def failed(self) -> OutputError | None:
        return self._file.failed

    def write(self, event: Event) -> None:
        self._file.write(event.to_json() + "\n")

    def close(self) -> None:
        self._file.close()


def is_mcap(path: str | os.PathLike[str]) -> bool:
    """Whether a record at ``path`` is written as MCAP (its name ends .mcap)."""
    return str(path).lower().endswith(MCAP_SUFFIX)


def open_record(path: str | os.PathLike[str], config: RobotConfig,
                channels: RunChannels | None = None) -> EventRecord:
    """The record at ``path``: MCAP for a name ending .mcap (on ``channels``
    when given: a live server's, which then sees what it records), else JSON
    lines.  Raises InputError when it cannot be opened, OutputError when an
    MCAP file's start cannot be written (a full disk)."""
    if is_mcap(path):
        from stairbot.recording.mcap_sink import McapRecord

        return McapRecord(path, config, channels=channels)
    return JsonLinesRecord(path)
