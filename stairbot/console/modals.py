"""Small modal screens: a yes/no question, one whose yes moves the robot
(typed, not a key), and a one-line text prompt.  The
emergency stop key (space) stays live over them: the app takes it before any
screen or widget sees it, so a prompt cannot take a space (and says so)."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label


class ConfirmScreen(ModalScreen[bool]):
    """Ask a yes/no question; dismisses with True only for an explicit yes."""

    BINDINGS = [Binding("y", "answer(True)", "yes"), Binding("n,escape", "answer(False)", "no")]

    def __init__(self, question: str, yes: str = "Yes, start (y)", no: str = "No (n)") -> None:
        super().__init__()
        self.question = question
        self.yes, self.no = yes, no

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog"):
            yield Label(self.question, classes="question", markup=False)
            with Horizontal(classes="buttons"):
                yield Button(self.yes, variant="warning", id="yes", compact=True)
                yield Button(self.no, variant="primary", id="no", compact=True)

    FOCUS = "#no"
    """What has the focus when the question opens (Textual calls each class's
    on_mount: a subclass names its own here)."""

    def on_mount(self) -> None:
        self.query_one(self.FOCUS).focus()

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.dismiss(event.button.id == "yes")

    def action_answer(self, yes: bool) -> None:
        self.dismiss(yes)


class MotionConfirm(ConfirmScreen, inherit_bindings=False):
    """A question whose yes lets the robot move: answered yes only by typing
    ``yes`` and Enter, which no stray letter gives -- typed text (a URL typed
    while a refusal showed) goes into the answer field, not to the console's
    keys or the buttons.  Anything else entered says so and asks again;
    Escape (or the No button) answers no."""

    BINDINGS = [Binding("escape", "answer(False)", "no")]
    FOCUS = "#answer"
    WORD = "yes"

    def __init__(self, question: str, yes: str = "Start", no: str = "No (Esc)") -> None:
        super().__init__(question, yes, no)

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog"):
            yield Label(self.question, classes="question", markup=False)
            yield Input(placeholder=f"type {self.WORD} and Enter: {self.yes}", id="answer")
            yield Label("Esc: no, nothing moves.", classes="hint", id="motion-hint",
                        markup=False)
            with Horizontal(classes="buttons"):
                yield Button(self.no, variant="primary", id="no", compact=True)

    def on_input_submitted(self, event: Input.Submitted) -> None:
        event.stop()
        if event.value.strip().lower() == self.WORD:
            self.dismiss(True)
            return
        event.input.value = ""
        self.query_one("#motion-hint", Label).update(
            f"Not {self.WORD}: nothing moved.  Type {self.WORD} and Enter, or Esc.")


class AskScreen(ModalScreen[str | None]):
    """Ask for one line of text (a URL, a file); Enter accepts, Escape cancels."""

    BINDINGS = [Binding("escape", "cancel", "cancel")]

    def __init__(self, title: str, value: str = "", placeholder: str = "",
                 hint: str = "") -> None:
        super().__init__()
        self.title_text = title
        self.value = value
        self.placeholder = placeholder
        self.hint = hint

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog"):
            yield Label(self.title_text, classes="question", markup=False)
            yield Input(value=self.value, placeholder=self.placeholder, id="answer")
            if self.hint:
                yield Label(self.hint, classes="hint", markup=False)
            yield Label("space is the EMERGENCY STOP even here: no spaces", classes="hint")

    def on_mount(self) -> None:
        self.query_one(Input).focus()

    def on_input_submitted(self, event: Input.Submitted) -> None:
        event.stop()
        self.dismiss(event.value.strip())

    def action_cancel(self) -> None:
        self.dismiss(None)


class ChoiceScreen(ModalScreen[str | None]):
    """A question with a few answers, each its own key; Escape (or n) answers
    None: nothing is done."""

    def __init__(self, question: str, choices: list[tuple[str, str]]) -> None:
        super().__init__()
        self.question = question
        self.choices = choices  # (key, label), e.g. ("r", "Resume (r)")
        for key, _ in choices:
            self._bindings.bind(key, f"choose({key!r})", show=False)
        self._bindings.bind("n,escape", "choose(None)", show=False)

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog"):
            yield Label(self.question, classes="question", markup=False)
            with Horizontal(classes="buttons"):
                for key, label in self.choices:
                    yield Button(label, id=f"choice-{key}", compact=True)
                yield Button("Cancel (n)", variant="primary", id="choice-none", compact=True)

    def on_mount(self) -> None:
        self.query_one("#choice-none", Button).focus()

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        key = (event.button.id or "").removeprefix("choice-")
        self.dismiss(None if key == "none" else key)

    def action_choose(self, key: str | None) -> None:
        self.dismiss(key)


class Notice(ModalScreen[None]):
    """Something the console will not do now, and why: Enter or Escape
    closes it; every other key is taken and does nothing (text typed on
    while it shows -- the URL the operator meant to enter -- runs no
    command)."""

    BINDINGS = [Binding("enter,escape", "close", "close")]

    def __init__(self, text: str) -> None:
        super().__init__()
        self.text = text

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog"):
            yield Label(self.text, classes="question", markup=False)
            yield Label("Enter or Esc closes this", classes="hint")

    def action_close(self) -> None:
        self.dismiss(None)
