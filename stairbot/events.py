"""The event stream: what the controller and the runner say, for logs and the console.

Listeners only listen; they never reach into the algorithm.  Every event
serialises to one JSON object (``to_json``), which is what ``--record`` writes.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any


class EventKind(StrEnum):
    PHASE = "phase"  # the controller entered a new phase
    PAUSE = "pause"  # the standing rule stopped the robot
    RESUME = "resume"  # readings agree again: resumed where it stopped
    INFO = "info"  # a measurement or decision worth telling
    WARNING = "warning"
    ERROR = "error"  # the program ends with an error
    LINK = "link"  # link health from a driver
    END = "end"  # the program ended (data holds the controller's result)
    SUMMARY = "summary"  # the run loop's summary after the end (data: RunResult)


@dataclass(frozen=True, slots=True)
class Event:
    time_s: float
    kind: EventKind
    message: str
    phase: str | None = None
    data: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {
            "time_s": round(self.time_s, 4),
            "kind": self.kind.value,
            "phase": self.phase,
            "message": self.message,
            "data": self.data,
        }

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True)

    def line(self) -> str:
        """One readable line for a terminal."""
        return f"[{self.time_s:8.2f} s] {self.kind.value:<7} {self.message}"


EventSink = Callable[[Event], None]


def discard(_event: Event) -> None:
    """An event sink that drops everything."""
