"""The emergency stop button, always on screen; its key (space) works everywhere."""

from __future__ import annotations

from textual.widgets import Button

ESTOP_KEY = "space"


class EStopButton(Button):
    """A red button that runs the app's ``estop`` action when pressed."""

    DEFAULT_CSS = """
    EStopButton { width: auto; min-width: 20; height: 1; }
    """

    def __init__(self, *, id: str | None = None) -> None:  # noqa: A002
        super().__init__("■ E-STOP (space)", variant="error", compact=True, id=id,
                         action="app.estop")
        self.can_focus = False  # space must never be taken by a focused button
