"""The scrolling event log: each event with its time on the controller's clock."""

from __future__ import annotations

from collections.abc import Iterable

from rich.text import Text
from textual.widgets import RichLog

from stairbot.events import Event, EventKind

KIND_STYLES = {
    EventKind.PHASE: "cyan",
    EventKind.PAUSE: "yellow",
    EventKind.RESUME: "green",
    EventKind.INFO: "",
    EventKind.WARNING: "bold yellow",
    EventKind.ERROR: "bold red",
    EventKind.LINK: "dim",
    EventKind.END: "bold",
    EventKind.SUMMARY: "bold",
}


def event_text(event: Event) -> Text:
    """``  12.34 s phase   ascent 3 — lift segment 1``"""
    line = Text(f"{event.time_s:8.2f} s ", "dim")
    line.append(f"{event.kind.value:<7} ", KIND_STYLES.get(event.kind, ""))
    line.append(event.message, KIND_STYLES.get(event.kind, "") if event.kind in (
        EventKind.ERROR, EventKind.WARNING, EventKind.END, EventKind.SUMMARY) else "")
    return line


class EventLog(RichLog):
    """Appends only the events it has not shown yet; keeps the last thousand."""

    DEFAULT_CSS = "EventLog { height: 1fr; }"

    def __init__(self, *, id: str | None = None) -> None:  # noqa: A002
        super().__init__(id=id, max_lines=1000, wrap=False, markup=False, auto_scroll=True)
        self.border_title = "events"
        self.last_seq = 0

    def add(self, events: Iterable[tuple[int, Event]]) -> None:
        for seq, event in events:
            if seq > self.last_seq:
                self.write(event_text(event))
                self.last_seq = seq

    def reset_log(self) -> None:
        self.clear()
