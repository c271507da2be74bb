"""A replay's timeline markers: the recording's errors, pauses and phase
changes, at their times on the replay's timeline, for the operator to jump
to (``,`` and ``.`` in a replay) and to see on the timeline under the plot.

Pure: no Textual here."""

from __future__ import annotations

from bisect import bisect_left, bisect_right
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from rich.text import Text

from stairbot.events import Event, EventKind

KINDS: dict[EventKind, tuple[str, str, str]] = {
    EventKind.ERROR: ("error", "E", "bold red"),
    EventKind.PAUSE: ("pause", "P", "bold yellow"),
    EventKind.PHASE: ("phase", "|", "cyan"),
}
"""The events marked: what the marker says, its mark on the timeline, its style."""


@dataclass(frozen=True)
class Marker:
    time_s: float
    """On the replay's timeline."""
    kind: str
    """"error", "pause" or "phase"."""
    text: str
    """The event's message."""

    def line(self) -> str:
        """``ERROR at 43.25 s: ...``."""
        return f"{self.kind.upper()} at {self.time_s:.2f} s: {self.text}"


def markers_of(events: Iterable[Event]) -> tuple[Marker, ...]:
    """The markers of ``events`` (time-ordered, as a recording's are)."""
    return tuple(Marker(e.time_s, KINDS[e.kind][0], e.message) for e in events
                 if e.kind in KINDS)


def step(markers: Sequence[Marker], position: float, direction: int) -> Marker | None:
    """The marker after ``position`` (``direction`` > 0) or before it (< 0);
    None: there is none that way.  A marker at the position itself is not
    "after" or "before" it: pressing again moves on."""
    times = [m.time_s for m in markers]
    if direction > 0:
        i = bisect_right(times, position + 1e-9)
        return markers[i] if i < len(markers) else None
    i = bisect_left(times, position - 1e-9)
    return markers[i - 1] if i > 0 else None


def timeline(markers: Sequence[Marker], start_s: float, end_s: float, position: float,
             width: int) -> Text:
    """One line ``width`` wide: the recording from start to end, each marker
    at its time (an error over a pause over a phase where they share a
    cell), and the position: ``█``, or the marker there reversed."""
    width = max(width, 2)
    span = max(end_s - start_s, 1e-9)

    def cell(t: float) -> int:
        return min(width - 1, max(0, round((t - start_s) / span * (width - 1))))

    cells: list[tuple[str, str]] = [("─", "dim")] * width
    rank = {"phase": 0, "pause": 1, "error": 2}
    best: dict[int, int] = {}
    by_name = {name: (mark, style) for name, mark, style in KINDS.values()}
    for m in markers:
        i = cell(m.time_s)
        if rank[m.kind] >= best.get(i, -1):
            best[i] = rank[m.kind]
            cells[i] = by_name[m.kind]
    out = Text(no_wrap=True, overflow="crop")
    here = cell(position)
    for i, (mark, style) in enumerate(cells):
        out.append("█" if i == here and mark == "─" else mark,
                   f"{style} reverse" if i == here and mark != "─" else style)
    return out
