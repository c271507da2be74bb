"""The connection manager (``u``): the robots this machine offers, grouped,
one line each (console/connections.py), and a URL field for anything not
listed.  Enter on a row, or on the field, dismisses with that URL, which
the console opens the way it opens every URL (``StairbotConsole.open_robot``:
a bad one is a message and the robot open before stays); Escape dismisses
with None and nothing changes; Enter on an empty field says what it
wants (:data:`EMPTY`) and the manager stays; ``r`` (outside the field), F5 or the button
looks again.  Looking runs on a worker thread: a slow source never holds
the screen, nor the emergency stop key, which the app takes before any
screen sees it.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, OptionList, Static
from textual.widgets.option_list import Option

from stairbot.console import connections
from stairbot.console.connections import GROUPS, Listing

EXAMPLES = "sim://  serial://PORT?baud=N  can://IF/CHANNEL"
SHOWN_URL = 100
"""A URL longer than this is shown cut (the row opens it whole)."""
EMPTY = "enter a URL or pick one from the list"
"""What Enter on an empty URL field says (the manager stays open)."""
NOTES_ROWS = 4
"""The rows the problems found have under the list."""


def _shown(url: str) -> str:
    return url if len(url) <= SHOWN_URL else f"{url[:SHOWN_URL - 1]}… ({len(url)} characters)"


def _fitted(problems: list[str]) -> list[str]:
    """The problems in the NOTES_ROWS the notes have: past them, how many
    more (a registry full of junk is a line each, and the rows past the
    last were cut without a word)."""
    if len(problems) <= NOTES_ROWS:
        return problems
    more = len(problems) - (NOTES_ROWS - 1)
    return [*problems[:NOTES_ROWS - 1], f"... and {more} more problems like these"]


class ConnectScreen(ModalScreen[str | None]):
    """Pick a robot from a list, or type its URL."""

    BINDINGS = [
        Binding("escape", "cancel", "close"),
        Binding("f5", "look", "look again"),
        Binding("r", "look", "look again", show=False),
    ]

    DEFAULT_CSS = """
    ConnectScreen { align: center middle; }
    ConnectScreen #connect {
        width: 100; max-width: 100%; height: 100%; max-height: 40;
        border: thick $warning; background: $surface; padding: 0 1;
    }
    ConnectScreen #robots { height: 1fr; min-height: 3; }
    ConnectScreen #connect-notes { color: $warning; height: auto; max-height: 4; }
    ConnectScreen #connect-notes.empty { display: none; }
    ConnectScreen #connect-why { color: $warning; width: 100%; height: auto; }
    ConnectScreen #connect-why.empty { display: none; }
    ConnectScreen .hint { color: $text-muted; width: 100%; }
    ConnectScreen .buttons { height: 1; align: center middle; }
    ConnectScreen Button { margin: 0 2; }
    """

    def __init__(self, current: str, sim: str,
                 gather: Callable[..., Listing] | None = None) -> None:
        super().__init__()
        self.current = current
        self.sim = sim
        self.gather = gather
        """What looks (None: :func:`connections.gather`, looked up at each look)."""
        self.urls: dict[str, str] = {}
        """Each openable row's option id -> its URL."""
        self.listing: Listing | None = None
        """What the last look found (None: still looking)."""

    def compose(self) -> ComposeResult:
        with Vertical(id="connect"):
            yield Label(f"Connect to a robot (open now: {_shown(self.current)})",
                        id="connect-title", markup=False)
            yield OptionList(id="robots")
            yield Static("", id="connect-notes", classes="empty", markup=False)
            yield Input(value=self.current, placeholder=EXAMPLES, id="url")
            yield Static("", id="connect-why", classes="empty", markup=False)
            yield Label("Enter opens the row, or the URL typed below · r/F5 looks again · "
                        "Esc closes · space is the EMERGENCY STOP even here: no spaces",
                        classes="hint", markup=False)
            with Horizontal(classes="buttons"):
                yield Button("Look again (F5)", id="look", compact=True)
                yield Button("Close (Esc)", variant="primary", id="close", compact=True)

    def on_mount(self) -> None:
        self.query_one(OptionList).focus()
        self.action_look()

    # -- looking ---------------------------------------------------------------------
    def action_look(self) -> None:
        robots = self.query_one(OptionList)
        robots.set_options([Option(Text("looking for robots...", style="italic"),
                                   disabled=True)])
        self.listing = None
        self.run_worker(self._look, thread=True, exclusive=True, group="connections")

    def _look(self) -> None:
        try:
            listing = (self.gather or connections.gather)(sim=self.sim)
        except Exception as exc:  # noqa: BLE001 - gather's sources cannot raise; a bug is a line
            listing = Listing(problems=[f"cannot look for robots: {type(exc).__name__}: {exc}"])
        self.app.call_from_thread(self._show, listing)

    def _show(self, listing: Listing) -> None:
        if not self.is_attached or self not in self.app.screen_stack:
            return  # closed while it looked (a closing screen loses its widgets first)
        options: list[Option] = []
        self.urls = {}
        for group in GROUPS:
            options.append(Option(Text(group, style="bold underline"), disabled=True))
            rows = listing.group(group)
            if not rows:
                options.append(Option(Text("  none found", style="italic"), disabled=True))
            for entry in rows:
                key = f"row-{len(self.urls)}"
                self.urls[key] = entry.url
                prompt = Text("  ")
                prompt.append(_shown(entry.url), style="bold")
                prompt.append(f"  {entry.description}", style="dim")
                options.append(Option(prompt, id=key))
        if listing.skipped:
            options.append(Option(Text("Not listed", style="bold underline"), disabled=True))
            options.extend(Option(Text(f"  {why}", style="italic"), disabled=True)
                           for why in listing.skipped)
        robots = self.query_one(OptionList)
        robots.set_options(options)
        robots.highlighted = self._first_row(options)
        self.query_one("#connect-title", Label).update(
            f"Connect to a robot (open now: {_shown(self.current)}) · as found at "
            f"{time.strftime('%H:%M:%S')}")
        notes = self.query_one("#connect-notes", Static)
        notes.update("\n".join(_fitted(listing.problems)))
        notes.set_class(not listing.problems, "empty")
        self.listing = listing

    def _first_row(self, options: list[Option]) -> int | None:
        """The row of the robot open now, else the first that opens one."""
        rows = [(i, o.id) for i, o in enumerate(options) if o.id in self.urls]
        for i, key in rows:
            if self.urls[key or ""] == self.current:
                return i
        return rows[0][0] if rows else None

    # -- choosing --------------------------------------------------------------------
    def on_option_list_option_selected(self, event: OptionList.OptionSelected) -> None:
        event.stop()
        url = self.urls.get(event.option.id or "")
        if url is not None:
            self.dismiss(url)

    def on_input_submitted(self, event: Input.Submitted) -> None:
        event.stop()
        url = event.value.strip()
        if not url:
            self.why(EMPTY)
            return
        self.dismiss(url)

    def on_input_changed(self, event: Input.Changed) -> None:
        if event.value.strip():
            self.why("")

    def why(self, words: str) -> None:
        """Say under the field why Enter did not open it ("": nothing)."""
        line = self.query_one("#connect-why", Static)
        line.update(words)
        line.set_class(not words, "empty")

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        if event.button.id == "look":
            self.action_look()
        else:
            self.dismiss(None)

    def action_cancel(self) -> None:
        self.dismiss(None)
