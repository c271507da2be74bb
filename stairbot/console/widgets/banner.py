"""The banner: which robot, the run's state, and the one thing the operator must
know now (an emergency stop, a lost link, how the run ended)."""

from __future__ import annotations

from rich.text import Text
from textual.widgets import Static

from stairbot.console.state import RunStatus

SEVERITY_CLASSES = ("-info", "-good", "-warning", "-error", "-estop")


def banner_text(url: str, scenario: str, status: RunStatus,
                recording: str | None = None, degraded: str = "") -> Text:
    """`` FAULT  E-STOP (automatic)  why...``: the robot's state, the latch and
    who set it, ``DEGRADED`` and how (``degraded``: the run limps home, or
    came home so), then the one thing to know now (whole: the banner wraps)."""
    state = "PAUSED" if status.paused and status.robot == "running" else status.robot.upper()
    out = Text(f" {state} ", "bold reverse")
    if status.estopped:
        who = status.latch.split(":", 1)[0] if status.latch else ""
        out.append(" ")
        out.append(" E-STOP ", "bold reverse")
        if who:
            out.append(f" ({who})", "bold")
    if recording:
        out.append(" ● REC", "bold")
    if degraded:
        out.append(" ")
        out.append(" DEGRADED ", "bold reverse")
        out.append(f" {degraded} ·", "bold")
    out.append(f" {status.message}" if status.message else f" {url or '—'} · {scenario}")
    return out


class Banner(Static):
    """One line, coloured by severity; red while the emergency stop is set."""

    DEFAULT_CSS = "Banner { height: auto; max-height: 6; width: 1fr; }"

    def __init__(self, *, id: str | None = None) -> None:  # noqa: A002
        super().__init__(id=id)
        self._last: object = None
        self.plain = ""  # the text shown, for tests and logs

    def show(self, url: str, scenario: str, status: RunStatus,
             recording: str | None = None, degraded: str = "") -> None:
        key = (url, scenario, status, recording, degraded)
        if key == self._last:
            return
        self._last = key
        text = banner_text(url, scenario, status, recording, degraded)
        self.plain = text.plain
        self.update(text)
        self.remove_class(*SEVERITY_CLASSES)
        self.add_class("-estop" if status.estopped else f"-{status.severity}")
