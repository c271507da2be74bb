"""The scrolling event log: each event with its time on the controller's clock;
a filter by kind (e cycles it) and a search (/) narrow what it lists."""

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
FILTERS: dict[str, frozenset[EventKind] | None] = {
    "all": None,
    "errors": frozenset({EventKind.ERROR}),
    "warnings": frozenset({EventKind.WARNING, EventKind.ERROR}),
    "phases": frozenset({EventKind.PHASE, EventKind.PAUSE, EventKind.RESUME, EventKind.END,
                         EventKind.SUMMARY}),
    "link": frozenset({EventKind.LINK}),
}
"""The kinds each filter lists (in the order e steps through them); "warnings"
lists the errors too."""
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
    writes them again, wrapped afresh, when its width changes or the filter
    or the search does.  Its title says what is filtered and how many of
    the events kept it lists.

    It is anchored to its end (Textual's ``anchor``): the newest event stays
    in view as events come and as the screen around it changes (the e-stop's
    banner takes rows from it), until the operator scrolls up to read; back
    at the end, it follows again."""

    DEFAULT_CSS = "EventLog { height: 1fr; }"

    def __init__(self, *, id: str | None = None) -> None:  # noqa: A002
        super().__init__(id=id, max_lines=4 * KEEP, min_width=1, wrap=True, markup=False,
                         auto_scroll=False)
        self.border_title = "events"
        self.last_seq = 0
        self._kept: deque[Event] = deque(maxlen=KEEP)
        self._width = 0
        self.kinds = "all"
        """The filter (a key of FILTERS)."""
        self.search = ""
        """Only events whose message holds this (any case); "": every one."""
        self.listed = 0  # events the log lists now

    def on_mount(self) -> None:
        self.anchor()

    def shows(self, event: Event) -> bool:
        kinds = FILTERS[self.kinds]
        return (kinds is None or event.kind in kinds) and \
            self.search.lower() in event.message.lower()

    def set_filter(self, kinds: str | None = None, search: str | None = None) -> None:
        """Filter by ``kinds`` (a key of FILTERS) and ``search`` (None: as it is)."""
        if kinds is not None:
            if kinds not in FILTERS:
                raise ValueError(f"filter {kinds!r}; allowed: {', '.join(FILTERS)}")
            self.kinds = kinds
        if search is not None:
            self.search = search
        self._write_all()

    def next_filter(self) -> str:
        """Step to the next filter (after the last: every event); returns it."""
        names = list(FILTERS)
        self.set_filter(names[(names.index(self.kinds) + 1) % len(names)])
        return self.kinds

    def _title(self) -> None:
        title = "events"
        if self.kinds != "all":
            title += f" · {self.kinds} only"
        if self.search:
            title += f" · holding {self.search!r}"
        if self.kinds != "all" or self.search:
            title += f" · {self.listed} of {len(self._kept)} (e, /)"
        self.border_title = title

    def _write_all(self) -> None:
        self.clear()
        self.listed = 0
        for kept in self._kept:
            if self.shows(kept):
                self.listed += 1
                if self._width:
                    self.write(event_row(kept, self._wide()), expand=True)
        self._title()

    def _wide(self) -> bool:
        return self.scrollable_content_region.width >= WIDE

    def add(self, new: Iterable[tuple[int, Event]]) -> None:
        filtered = self.kinds != "all" or bool(self.search)
        for seq, event in new:
            if seq > self.last_seq:
                if filtered and len(self._kept) == KEEP and self.shows(self._kept[0]):
                    self.listed -= 1  # the oldest kept goes
                self._kept.append(event)
                self.last_seq = seq
                if self.shows(event):
                    self.listed += 1
                    if self._width:  # else on_resize writes it, once the width is known
                        self.write(event_row(event, self._wide()), expand=True)
        if filtered:
            self._title()

    def on_resize(self, event: events.Resize) -> None:
        """Write every kept event again, wrapped for the new width (RichLog
        keeps lines as first rendered)."""
        if event.size.width != self._width:
            self._width = event.size.width
            self._write_all()

    def reset_log(self) -> None:
        self.clear()
        self._kept.clear()
        self.listed = 0
        self._title()
