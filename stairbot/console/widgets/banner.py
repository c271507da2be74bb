"""The banner: its first line a strip that says which robot and whether it is
live, always (the run's state and latch, then LIVE/DOWN and the age of the
last reading, the boards, the URL: cut at the screen's edge, never wrapped);
under it, while there is one, the one thing the operator must know now (an
emergency stop, a lost link, how the run ended), whole up to four lines, or
fewer where the screen has no more rows to spare (:attr:`Banner.room`:
80x24 keeps one, so the right column's panels stay on the screen; a
FAULT's reason keeps all four); a
longer one is cut there, and told whole to ``told`` (the event list) once."""

from __future__ import annotations

from collections.abc import Callable

from rich.console import Group
from rich.text import Text
from textual.widgets import Static

from stairbot.console.freshness import is_stale
from stairbot.console.state import RunStatus

SEVERITY_CLASSES = ("-info", "-good", "-warning", "-error", "-estop")
MESSAGE_LINES = 4
"""The banner's lines for its message, under the strip (its max-height: 5)."""
CUT = " … (whole in the events)"
CUT_SHORT = " …"
"""The cut of a message kept to one line (80x24), where every column counts;
the message is the event list's newest line, whole."""


def liveness(age_s: float | None, status: RunStatus) -> str:
    """``LIVE 0.2 s``, ``DOWN 12 s`` (nothing read for longer than a stale
    value's age, or the robot at fault), ``NOT READ`` (nothing read yet)."""
    if age_s is None:
        return "NOT READ"
    shown = f"{age_s:.1f} s" if age_s < 10 else f"{age_s:.0f} s"
    if is_stale(age_s) or status.robot == "fault":
        return f"DOWN {shown}"
    return f"LIVE {shown}"


def strip_text(url: str, scenario: str, status: RunStatus, recording: str | None = None,
               degraded: str = "", link: str = "", boards: str = "",
               place: bool = True, watching: bool = False) -> Text:
    """`` FAULT  E-STOP (automatic) · DOWN 12 s · motor #12 · serial://...``:
    the robot's state, the latch and who set it, ``DEGRADED`` and how
    (``degraded``: the run limps home, or came home so), the link's word
    (:func:`liveness`), the boards, the URL and scenario (``place``; a
    replay's message says its own) -- one line.  ``watching``: another
    console controls the robot (console/sharing.py), said first."""
    out = Text(no_wrap=True, overflow="ellipsis")
    if watching:
        out.append(" WATCHING ", "bold reverse")
        out.append(" ")
    # a run held by the latch is in the e-stop state, not merely paused
    if not (status.estopped and status.robot == "running"):
        state = "PAUSED" if status.paused and status.robot == "running" \
            else status.robot.upper()
        out.append(f" {state} ", "bold reverse")
        if status.estopped:
            out.append(" ")
    if status.estopped:
        who = status.latch.split(":", 1)[0] if status.latch else ""
        out.append(" E-STOP ", "bold reverse")
        if who:
            out.append(f" ({who})", "bold")
    if recording:
        out.append(" ● REC", "bold")
    if degraded:
        out.append(" ")
        out.append(" DEGRADED ", "bold reverse")
        out.append(f" {degraded}", "bold")
    if link:
        out.append(" · ")
        out.append(link, "bold")
    if boards:
        out.append(f" · {boards}")
    if place:
        out.append(f" · {url or '—'}" + (f" · {scenario}" if scenario else ""))
    return out


def message_text(url: str, message: str) -> Text:
    """The message with the URL (which the strip shows) said as "the robot",
    once: a long URL must not hide the reason (``no reading from the robot:
    URL: link lost`` reads ``no reading from the robot: link lost``).  A
    command in backquotes keeps its URL: ``stairbot clear --robot URL`` is
    typed as it is shown."""
    if url:
        parts = message.split("`")
        message = "`".join(
            part.replace(f": {url}: ", ": ").replace(url, "the robot") if i % 2 == 0
            else part for i, part in enumerate(parts))
    return Text(f" {message}")


class Banner(Static):
    """The strip, and the message under it; coloured by severity, red while
    the emergency stop is set."""

    DEFAULT_CSS = "Banner { height: auto; max-height: 5; width: 1fr; }"

    def __init__(self, *, id: str | None = None,  # noqa: A002
                 told: Callable[[str, str], None] | None = None) -> None:
        """``told(message, severity)``: a message too long to show whole goes
        there whole, once (the console's event list)."""
        super().__init__(id=id)
        self._told = told
        self._cut: str = ""  # the last message cut, told already
        self._last: object = None
        self.plain = ""  # the text shown, for tests and logs
        self.strip = ""  # its first line
        self.room = MESSAGE_LINES
        """The lines the message may take now (console/roomy.py: message_rows)."""

    def show(self, url: str, scenario: str, status: RunStatus, recording: str | None = None,
             degraded: str = "", link: str = "", boards: str = "", replay: bool = False,
             watching: bool = False) -> None:
        """``replay``: a recording played back -- no robot, so no strip: the
        state, then the message (the recording's place and source) as it is.
        ``watching``: another console controls the robot shown."""
        width = self.content_region.width
        key = (url, scenario, status, recording, degraded, link, boards, replay, watching,
               width, self.room)
        if key == self._last:
            return
        self._last = key
        if replay and status.message:
            strip = strip_text(url, scenario, status, recording, degraded, place=False)
            whole = strip.copy()
            whole.no_wrap = False
            whole.append(f" {status.message}")
            self.strip, self.plain = strip.plain, whole.plain
            self.update(whole)
        else:
            strip = strip_text(url, scenario, status, recording, degraded, link, boards,
                               watching=watching)
            self.strip = strip.plain
            if not status.message:
                self.plain = strip.plain
                self.update(strip)
            else:
                message = message_text(url, status.message)
                if 0 < strip.cell_len + 2 + message.cell_len <= width:  # one line holds both
                    line = strip.copy()
                    line.append(" │")
                    line.append_text(message)
                    self.plain = line.plain
                    self.update(line)
                else:
                    message = self._fit(message, width, status)
                    self.plain = f"{strip.plain}\n{message.plain}"
                    self.update(Group(strip, message))
        self.remove_class(*SEVERITY_CLASSES)
        self.add_class("-estop" if status.estopped else f"-{status.severity}")

    def _fit(self, message: Text, width: int, status: RunStatus) -> Text:
        """``message`` whole if it wraps to :attr:`room` lines at ``width``;
        else its first lines, the last ending in CUT, and the whole told once."""
        if width <= len(CUT) + 1:
            return message
        lines = message.wrap(self.app.console, width)
        room = max(1, min(self.room, MESSAGE_LINES))
        if len(lines) <= room:
            return message
        last = lines[room - 1]
        cut = CUT if room > 1 else CUT_SHORT
        if room == 1:  # the line as the width holds it, not as it wrapped
            last = message.copy()
            last.no_wrap = True
        last.truncate(width - len(cut))
        last.rstrip()
        last.append(cut)
        if self._told is not None and self._cut != status.message:
            self._cut = status.message
            self._told(status.message, status.severity)
        return Text("\n").join([*lines[:room - 1], last])
