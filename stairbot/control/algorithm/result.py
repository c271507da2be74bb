"""How the program ended, as the controller reports it."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from stairbot.control.algorithm.modes import Outcome

OUTCOMES = tuple(o.value for o in Outcome)


@dataclass(frozen=True)
class ControllerResult:
    """How the program ended (``outcome`` is "running" until it has)."""

    outcome: str  # an Outcome's value, or "running"
    ascent_end: str | None  # an AscentEnd's value, or None
    error: str | None
    steps_climbed: int
    steps_descended: int
    pauses: int
    reason: str | None = None  # why it ended, whatever the outcome

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)
