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
from typing import TYPE_CHECKING

from stairbot.console.modals import MotionConfirm
from stairbot.console.sharing import (
    MirrorState,
    Reply,
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
                on_ask=lambda who, reply: app.call_from_thread(_asked, app, who, reply))
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


def watch(app: StairbotConsole, url: str) -> bool:
    """Watch the console that holds ``url`` (False: none shares it)."""
    stop_watching(app)
    state = app.state
    if not isinstance(state, MirrorState):
        return False
    client = connect(url, state, lambda kind, text, severity: app.call_from_thread(
        _replied, app, kind, text, severity))
    if client is None:
        return False
    state.watch(f"the console that opened {url} first")
    app.sharing.client = client
    return True


def stop_watching(app: StairbotConsole) -> None:
    client, app.sharing.client = app.sharing.client, None
    if client is not None:
        client.close()
    if isinstance(app.state, MirrorState):
        app.state.unwatch()


def close(app: StairbotConsole) -> None:
    """The console quits: stop sharing and watching."""
    unshare(app)
    client, app.sharing.client = app.sharing.client, None
    if client is not None:
        client.close()


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
    app.call_from_thread(_withdraw_question, app)
    return "emergency stop latched by the controlling console (c there clears it)"


def _withdraw_question(app: StairbotConsole) -> None:
    from stairbot.console import limp_question

    limp_question.withdraw(app)
    app.refresh_view()


def _asked(app: StairbotConsole, who: str, reply: Reply) -> None:
    """Another console asks for control (the UI thread)."""
    if app.engine.running:
        reply(False, "a run is going on: the console that controls it must stop it or "
                     "let it end first")
        app.say(f"{who} asked for control: refused while the run goes on", "warning")
        return
    if app.sharing.asked:
        reply(False, "its operator is being asked already")
        return
    app.sharing.asked = True

    def answered(yes: bool | None) -> None:
        app.sharing.asked = False
        if not yes:
            reply(False, "its operator kept control")
            app.say(f"control kept: {who} was told no")
        elif app.engine.running:
            reply(False, "a run began meanwhile")
        else:
            _hand_over(app, who, reply)

    app.push_screen(MotionConfirm(
        f"{who.capitalize()} asks for control of {app.url}.\n\nHand it over? This console "
        "then closes the robot and watches it; the robot does not move.",
        yes="Hand over", no="Keep it (Esc)"), answered)


def _hand_over(app: StairbotConsole, who: str, reply: Reply) -> None:
    """Close the robot, tell the asker it may open it, then watch it (a
    worker thread waits for the asker to share it)."""
    app.engine.close()
    app.state.set_status(robot="no robot", severity="info",
                         message=f"control handed to {who}")
    reply(True, f"control handed over by {whoami()}")
    unshare(app)
    url = app.url

    def watch_new_controller() -> None:
        deadline = time.monotonic() + TAKE_OVER_WAIT_S
        while time.monotonic() < deadline:
            if app.sharing.client is not None or app.engine.session is not None:
                return
            if watch(app, url):
                app._tell(f"watching {url}: {who} controls it now", "information")
                return
            time.sleep(0.1)
        app._tell(f"{who} did not open {url}: u opens it here", "warning")

    threading.Thread(target=watch_new_controller, name="watch the new controller",
                     daemon=True).start()


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
        client, app.sharing.client = app.sharing.client, None
        if client is not None:
            client.close()
        app.say(f"the console that controlled {app.url} no longer answers; u opens the "
                "robot here", "warning")
