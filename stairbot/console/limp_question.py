"""The operator's consent to limp home, asked when a console run ends on a
degraded stop (:mod:`stairbot.console.limp_gate` says when it can be).

The question shows the stop plainly -- what failed, where the robot stands,
the lifts holding, what limping home will do and at what speed -- and
takes one of two answers: come home on the remaining sensors (``yes``
typed, then Enter: no stray key gives it), which carries the same program
on in this session, or stay stopped (Escape),
which leaves the robot stopped, lifts holding, the stop's emergency stop
latched, and says how to bring it home later.  Space (the emergency stop)
withdraws the question: the robot stays stopped.  Quitting leaves it
stopped too: the run already ended in the stop.  Where too little remains
there is no question: the console says it stays stopped and why.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, Label

from stairbot.console import limp_gate
from stairbot.console.modals import MotionConfirm
from stairbot.text import printable

if TYPE_CHECKING:
    from stairbot.console.app import StairbotConsole


class LimpQuestion(MotionConfirm):
    """Come home on the remaining sensors (True: ``yes`` typed, then Enter) or
    stay stopped (False: Escape); quitting from here (Escape, then q) leaves
    the robot stopped (the run has ended)."""

    def on_mount(self) -> None:
        super().on_mount()
        self.query_one(".dialog").add_class("wide")


class StopNotice(ModalScreen[None]):
    """A degraded stop with nothing to ask: what happened and why it stays."""

    BINDINGS = [("enter,escape,n,y", "close", "close")]

    def __init__(self, text: str) -> None:
        super().__init__()
        self.text = text

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog wide"):
            yield Label(self.text, classes="question", markup=False)
            with Horizontal(classes="buttons"):
                yield Button("OK (enter)", variant="primary", id="ok", compact=True)

    def on_mount(self) -> None:
        self.query_one("#ok", Button).focus()

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.dismiss(None)

    def action_close(self) -> None:
        self.dismiss(None)


def later(app: StairbotConsole) -> str:
    """How to bring the robot home later, in the words the CLI uses where
    they hold (boards: the journal resumes); the simulation's world ends
    with this console, so for it only the console's own way."""
    here = "l asks again here"
    if app.engine.in_process:
        return (f"{here} (a simulation cannot be carried on once the console closes: "
                "its world ends with it)")
    return (f"{here}; or, once this console is closed, `stairbot run --robot "
            f"{printable(app.url)} --resume --yes` carries this run on home from its journal")


def after_stop(app: StairbotConsole) -> None:
    """After a run that ended on a degraded stop: ask (:func:`ask`), or,
    with nothing to ask, say why the robot stays stopped."""
    stop = app.state.view().degraded
    if app.engine.limp_offer is not None:
        ask(app)
    elif stop is not None and (app.engine.limp_refused or limp_gate.stranded(stop)):
        per_turn = app.engine.config.motors.lift_travel_per_turn
        refused = app.engine.limp_refused
        why = limp_gate.cannot(refused) if refused else stop.data["degraded"].get("why", "")
        lines = limp_gate.stop_lines(stop, per_turn)
        app.push_screen(StopNotice("\n".join(
            [*lines, "", f"No question to ask: {why}.  A person brings it down (look at the "
             "robot first); c clears the emergency stop."])))


def ask(app: StairbotConsole) -> None:
    """The question (key l, or the mid-climb choice): only while there is a
    degraded stop this console can carry on, no run goes on, and no
    emergency stop of the operator's is set."""
    offer = app.engine.limp_offer
    if offer is None:
        app.say("no degraded stop to limp home from", "warning")
        return
    if app.engine.running:
        app.say("a run is going on", "warning")
        return
    if app.state.view().status.latch == "operator":
        app.say("the emergency stop is set: c clears it (look at the robot), then l asks "
                "again", "warning")
        return
    if isinstance(app.screen, LimpQuestion):
        return
    per_turn = app.engine.config.motors.lift_travel_per_turn
    lines = limp_gate.stop_lines(offer.stop, per_turn)
    wire = "" if app.engine.in_process else f" on {printable(app.url)} (boards on a wire)"
    question = "\n".join([
        *lines, "",
        "It can come down on the sensors that remain.  " + limp_gate.plan_words(offer.stop),
        "",
        f"Come home{wire}?  Yes clears the stop's emergency stop and the robot moves: look "
        "at it first.  Space stops every motor."])

    def answered(yes: bool | None) -> None:
        if yes and app.state.view().status.latch != "operator":
            app.limp_home()
            return
        pressed = app.state.view().status.latch == "operator"
        why = "the emergency stop was pressed" if pressed else "stay stopped"
        app.say(f"not moved ({why}): the robot stays stopped, lifts holding; to bring it "
                f"home later: {later(app)}", "warning", timeout=12)
        if not pressed:  # else the banner says how to clear the operator's stop
            app.state.set_status(message=f"DEGRADED STOP, stays stopped, lifts holding; to "
                                 f"bring it home later: {later(app)}", severity="warning")

    app.push_screen(LimpQuestion(question, yes="Come home on what remains",
                                 no="Stay stopped (Esc)"), answered)


def withdraw(app: StairbotConsole) -> None:
    """The emergency stop was pressed: a question open is withdrawn (its
    answer could no longer be acted on) and counts as "stay stopped"."""
    if isinstance(app.screen, LimpQuestion):
        app.screen.dismiss(False)
