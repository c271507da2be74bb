"""The console's side of one controller and many viewers (console/sharing.py).

A console that opens a robot on a locked URL shares it; one that finds the
robot held by a sharing console watches it instead of being refused.  While
watching, the keys that would reach a robot say who controls it and do
nothing else; the emergency stop goes to the controlling console, which
latches it; ``h`` asks for control, which the controlling console's operator
hands over (by typing yes: a question nobody asked for must not be answered
by a stray key) only while no run goes on.  Each function takes the console
app (:class:`~stairbot.console.app.StairbotConsole`).
"""

from __future__ import annotations

import errno
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

from textual.screen import ModalScreen

from stairbot.console.mirror import MirrorState
from stairbot.console.modals import MotionConfirm
from stairbot.console.sharing import (
    Request,
    ShareClient,
    ShareHub,
    connect,
    share_address,
    whoami,
)

if TYPE_CHECKING:
    from stairbot.console.app import StairbotConsole

CONTROL_ACTIONS = frozenset({
    "clear_estop", "start", "pause", "stop_run", "limp_home", "choose_scenario", "speed",
    "reset", "record",
})
"""Actions that reach the robot or its run: a watching console's say who controls it."""
TAKE_OVER_WAIT_S = 30.0
"""How long a console that handed control over waits to watch the new controller."""
HUB_WAIT_S = 2.0
"""How long a console that took control over waits for the old hub's address."""
SHARE_WAIT_S = 3.0
"""How long a console that finds the robot held waits for its holder to share
it (a console still opening it does once the boards answer)."""


class Sharing:
    """What the console shares (its hub) or watches (its client)."""

    def __init__(self) -> None:
        self.hub: ShareHub | None = None
        self.client: ShareClient | None = None
        self.asked = False
        """A request for control is being put to this console's operator."""


def is_watching(app: StairbotConsole) -> bool:
    return isinstance(app.state, MirrorState) and app.state.watching


def share(app: StairbotConsole) -> None:
    """The console opened its robot: share it, when a lock guards it (the
    worker thread that opened it)."""
    unshare(app)
    address = share_address(app.url)
    if address is None:
        return
    deadline = time.monotonic() + HUB_WAIT_S
    while True:
        try:
            app.sharing.hub = ShareHub(
                address, app.state,
                on_estop=lambda who: _estop_from(app, who),
                on_ask=lambda request: app.from_thread(_asked, app, request))
            return
        except OSError as exc:
            # a console that handed control over here closes its hub just after
            if exc.errno != errno.EADDRINUSE or time.monotonic() > deadline:
                app._tell(f"not shared with other consoles: {exc}", "warning")
                return
            time.sleep(0.05)


def unshare(app: StairbotConsole) -> None:
    hub, app.sharing.hub = app.sharing.hub, None
    if hub is not None:
        hub.close()


def watch(app: StairbotConsole, url: str, wait_s: float = 0.0) -> bool:
    """Watch the console that holds ``url``, trying for up to ``wait_s`` (a
    console still opening the robot shares it once it answers); False: none
    shares it, or this console holds a robot itself.  What a hub that went
    quiet showed stays on screen meanwhile."""
    _drop_client(app)
    state = app.state
    if not isinstance(state, MirrorState):
        return False
    deadline = time.monotonic() + wait_s
    while True:
        if app.sharing.hub is not None or app.engine.session is not None:
            return False
        client = connect(url, state, lambda kind, text, severity: app.from_thread(
            _replied, app, kind, text, severity))
        if client is not None:
            break
        if time.monotonic() >= deadline:
            return False
        time.sleep(0.1)
    state.watch("another console")
    app.sharing.client = client
    return True


def _drop_client(app: StairbotConsole) -> None:
    """Close the connection to the hub watched, if any (the screen keeps what it showed)."""
    client, app.sharing.client = app.sharing.client, None
    if client is not None:
        client.close()


def stop_watching(app: StairbotConsole) -> None:
    _drop_client(app)
    if isinstance(app.state, MirrorState):
        app.state.unwatch()


def close(app: StairbotConsole) -> None:
    """The console quits: stop sharing and watching."""
    unshare(app)
    _drop_client(app)


def blocked(app: StairbotConsole, action: str) -> bool:
    """Whether ``action`` is refused because another console controls the
    robot (and the operator told so)."""
    if action not in CONTROL_ACTIONS or not is_watching(app):
        return False
    app.say("watching: another console controls this robot; h asks it for control",
            "warning")
    return True


def estop(app: StairbotConsole) -> bool:
    """The emergency stop pressed while watching: sent to the controlling
    console.  False when not watching (the console's own stop applies)."""
    client = app.sharing.client
    if client is None or not is_watching(app):
        return False
    if client.send("estop"):
        app.say("emergency stop sent to the console that controls the robot", "warning")
    else:
        app.say("the controlling console no longer answers: nothing was stopped from here",
                "error")
    return True


def ask_control(app: StairbotConsole) -> None:
    """``h``: ask the controlling console for control."""
    client = app.sharing.client
    if client is not None and is_watching(app):
        if client.send("ask"):
            app.say("asked the controlling console for control: its operator decides")
        else:
            app.say("the controlling console no longer answers", "warning")
    elif app.sharing.hub is not None:
        app.say("this console controls the robot; another console's h asks it for control")
    else:
        app.say("no other console controls the robot here: nothing to ask")


# -- the controlling console ------------------------------------------------------
def _estop_from(app: StairbotConsole, who: str) -> str:
    """A watching console's emergency stop (the hub's thread): latched here at once."""
    app.engine.estop(f"pressed in {who}")
    app.from_thread(_withdraw_question, app)
    return "emergency stop latched by the controlling console (c there clears it)"


def _withdraw_question(app: StairbotConsole) -> None:
    from stairbot.console import limp_question

    limp_question.withdraw(app)
    app.refresh_view()


def _asked(app: StairbotConsole, request: Request) -> None:
    """Another console asks for control (the UI thread)."""
    who = request.who
    if app.engine.running:
        request.answer(False, "a run is going on: the console that controls it must stop "
                              "it or let it end first")
        app.say(f"{who} asked for control: refused while the run goes on", "warning")
        return
    if app.sharing.asked:
        request.answer(False, "its operator is being asked already")
        return
    if isinstance(app.screen, ModalScreen):  # a yes typed for that question must not hand over
        request.answer(False, "its operator is answering another question there; ask again")
        app.say(f"{who} asked for control while a question was open: told to ask again",
                "warning")
        return
    app.sharing.asked = True

    def answered(yes: bool | None) -> None:
        app.sharing.asked = False
        if not request.alive:
            app.say(f"{who} has gone: control kept")
        elif not yes:
            request.answer(False, "its operator kept control")
            app.say(f"control kept: {who} was told no")
        elif app.engine.running:
            request.answer(False, "a run began meanwhile")
        else:
            _hand_over(app, request)

    app.push_screen(MotionConfirm(
        f"{who.capitalize()} asks for control of {app.url}.\n\nHand it over? This console "
        "then closes the robot and watches it; the robot does not move.",
        yes="Hand over", no="Keep it (Esc)"), answered)


def _hand_over(app: StairbotConsole, request: Request) -> None:
    """Close the robot, tell the asker it may open it, then watch it (a
    worker thread waits for the asker to share it)."""
    who = request.who
    app.engine.close()
    app.state.set_status(robot="no robot", severity="info",
                         message=f"control handed to {who}")
    request.answer(True, f"control handed over by {whoami()}")
    unshare(app)  # the answer goes first: the hub's thread sends it before it closes
    url = app.url

    def watch_new_controller() -> None:
        if watch(app, url, wait_s=TAKE_OVER_WAIT_S):
            app._tell(f"watching {url}: {who} controls it now", "information")
        elif app.engine.session is None and app.sharing.client is None:
            app._tell(f"{who} did not open {url}: u opens it here", "warning")

    _background(app, "watch the new controller", watch_new_controller)


def _background(app: StairbotConsole, name: str, work: Callable[[], None]) -> None:
    """Run ``work`` on a thread of its own; what fails there once the console
    has quit (no screen left to tell) is let go."""
    def run() -> None:
        try:
            work()
        except Exception:
            if app.is_running:
                raise

    threading.Thread(target=run, name=name, daemon=True).start()


# -- the watching console --------------------------------------------------------
def _replied(app: StairbotConsole, kind: str, text: str, severity: str) -> None:
    """What the controlling console said back (the UI thread)."""
    if kind == "said":
        app.say(text, severity)
    elif kind == "refused":
        app.say(f"control not handed over: {text}", "warning")
    elif kind == "granted":
        stop_watching(app)
        app.say(f"{text}: opening the robot here")
        app.open_robot(app.url, app.scenario)
    elif kind == "gone":
        _drop_client(app)
        app.say(f"the console that controlled {app.url} no longer answers; u opens the "
                "robot here", "warning")
        url = app.url

        def rewatch() -> None:  # it may have handed control to another
            if watch(app, url, wait_s=TAKE_OVER_WAIT_S / 3):
                app._tell(f"watching {url} again: another console controls it now",
                          "information")

        _background(app, "watch again", rewatch)
