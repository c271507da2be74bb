"""The scrolling event log: each event with its time on the controller's clock."""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable

from rich.table import Table
from rich.text import Text
from textual import events
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
LOUD = (EventKind.ERROR, EventKind.WARNING, EventKind.END, EventKind.SUMMARY)
WIDE = 60  # columns from which each event's kind gets a column of its own
KEEP = 300  # events kept, and written again when the width changes (~0.5 ms each)


def event_row(event: Event, wide: bool) -> Table:
    """``  12.34 s phase   ascent 3 — lift segment 1``: the message wraps under
    itself instead of being cut.  Narrow (``wide`` false), the kind has no
    column and shows only as the message's colour."""
    style = KIND_STYLES.get(event.kind, "")
    row = Table.grid(padding=(0, 1), expand=True)
    row.add_column(no_wrap=True, style="dim")
    if wide:
        row.add_column(no_wrap=True, width=7, style=style)
    row.add_column(ratio=1, overflow="fold")
    time = f"{event.time_s:8.2f} s" if wide else f"{event.time_s:7.2f}"
    message = Text(event.message, style if (event.kind in LOUD or not wide) else "")
    if wide:
        row.add_row(time, event.kind.value, message)
    else:
        row.add_row(time, message)
    return row


class EventLog(RichLog):
    """Appends only the events it has not shown yet; keeps the last KEEP, and
    writes them again, wrapped afresh, when its width changes."""

    DEFAULT_CSS = "EventLog { height: 1fr; }"

    def __init__(self, *, id: str | None = None) -> None:  # noqa: A002
        super().__init__(id=id, max_lines=4 * KEEP, min_width=1, wrap=True, markup=False,
                         auto_scroll=True)
        self.border_title = "events"
        self.last_seq = 0
        self._kept: deque[Event] = deque(maxlen=KEEP)
        self._width = 0

    def _wide(self) -> bool:
        return self.scrollable_content_region.width >= WIDE

    def add(self, new: Iterable[tuple[int, Event]]) -> None:
        for seq, event in new:
            if seq > self.last_seq:
                self._kept.append(event)
                self.last_seq = seq
                if self._width:  # else on_resize writes it, once the width is known
                    self.write(event_row(event, self._wide()), expand=True)

    def on_resize(self, event: events.Resize) -> None:
        """Write every kept event again, wrapped for the new width (RichLog
        keeps lines as first rendered)."""
        if event.size.width != self._width:
            self._width = event.size.width
            self.clear()
            for kept in self._kept:
                self.write(event_row(kept, self._wide()), expand=True)

    def reset_log(self) -> None:
        self.clear()
        self._kept.clear()
