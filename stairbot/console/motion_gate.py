"""When the console lets the robot move: the operator's consent.

Starting, resuming, clearing the emergency stop and quitting mid-run each
go through here.  The in-process simulation moves when told; a robot on a
wire (fake boards too: that they are simulated is only their own word) is
asked about first; a robot that may stand part way up the stairs is not
started fresh at all (:mod:`stairbot.console.climb_gate`).  Each function
takes the console app whose action it carries out
(:class:`~stairbot.console.app.StairbotConsole` binds the keys to them).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from stairbot.console import limp_question
from stairbot.console.climb_gate import MidClimb
from stairbot.console.engine import MID_CLIMB_HINT
from stairbot.console.modals import ChoiceScreen, ConfirmScreen, MotionConfirm
from stairbot.console.robot_holder import LATCH_HINT
from stairbot.errors import StairbotError

if TYPE_CHECKING:
    from stairbot.console.app import StairbotConsole

LOOK_FIRST = ("Look at the robot first: it may stand part way up a step, and the next run "
              "starts from where it stands.")


def clear_estop(app: StairbotConsole) -> None:
    """Clear the emergency stop -- the console's latch, or the latches of
    boards refused for holding one -- once the operator confirms."""
    pending = app.engine.latched_boards
    if pending is not None and app.engine.session is None:
        url, scenario, why = pending
        question = (f"{why}\n\n{LOOK_FIRST}\nClear the latches the boards hold?")

        def clear_boards(yes: bool | None) -> None:
            if yes:
                app.open_robot(url, scenario, clear_latches=True)
            else:
                app.say("not cleared: the boards keep their latches")

        app.push_screen(ConfirmScreen(question, yes="Yes, clear (y)"), clear_boards)
        return
    if not app.engine.estop_set:
        app.say("the emergency stop is not set")
        return

    def clear(yes: bool | None) -> None:
        if not yes:
            app.say("not cleared: the emergency stop stays latched")
        elif not app.engine.clear_estop():
            app.say("the emergency stop is not set")
        app.refresh_view()

    then = "p resumes the run" if app.engine.running else "s starts a run"
    app.push_screen(ConfirmScreen(
        f"Clear the EMERGENCY STOP?\n{LOOK_FIRST}\nClearing moves nothing: {then}.",
        yes="Yes, clear (y)"), clear)


def start(app: StairbotConsole, mode: str) -> None:
    """Start a run (``mode``: "full" or "calibrate"): not with the emergency
    stop latched, a run going on or no robot open; from part way up only by
    :func:`_mid_climb`'s choices; on a wire once the operator consents."""
    if app.engine.estop_set:
        app.state.set_status(message=LATCH_HINT, severity="error")
        app.say(LATCH_HINT, "error")
        return
    if app.engine.running:
        app.say("a run is already going on", severity="warning")
        return
    if app.engine.session is None:
        app.say("no robot open: choose one with u", severity="error")
        return
    if app.engine.mid_climb is not None:
        _mid_climb(app, mode, app.engine.mid_climb)
        return
    what = "Start calibration" if mode == "calibrate" else "Start the full run"
    after_consent(app, what, lambda: app.run_program(mode))


def _mid_climb(app: StairbotConsole, mode: str, gate: MidClimb) -> None:
    """The robot may stand part way up: no fresh start from there.  Offer
    what is safe -- resume (boards: the journal's run, checked first),
    reset (the simulation), or the operator's word that it is back at
    the start -- and move nothing until one is chosen and confirmed."""
    wired = not app.engine.in_process
    lines = "\n".join(gate.lines)
    question = (f"The robot may stand part way up the stairs:\n{lines}\n\n"
                "A new run would square up and drive at the riser from there: not "
                "started.  " + ("Resume carries on the journal's run, after checks"
                                if wired else "Reset puts the simulated robot at the start")
                + "; or say the robot is back at the start.")
    first = ("r", "Resume (r)") if wired else ("r", "Reset (r)")
    offered = [first, ("b", "Back at start (b)")]
    if app.engine.limp_offer is not None:  # the last run stopped degraded: it can come home
        question += "  Limp home asks whether it may come down on the sensors that remain."
        offered.insert(0, ("l", "Limp home (l)"))

    def chosen(key: str | None) -> None:
        if key == "l":
            limp_question.ask(app)
        elif key == "r":
            if wired:
                _resume(app, mode)
            else:
                app.action_reset()
        elif key == "b":
            app.push_screen(ConfirmScreen(
                "Start a new run from where the robot stands?\nOnly if it stands on the "
                "floor before the first step: a new run squares up, then drives at the "
                "stairs.", yes="Yes, it is at the start (y)"), back)
        else:
            app.say("nothing moved")

    def back(yes: bool | None) -> None:
        if yes:
            app.engine.back_at_start()
            app.action_start(mode)
        else:
            app.say("nothing moved")

    app.state.set_status(message=MID_CLIMB_HINT, severity="error")
    app.push_screen(ChoiceScreen(question, offered), chosen)


def _resume(app: StairbotConsole, mode: str) -> None:
    """Check the journal's run against the boards, show where the robot
    believes it is, and carry it on once the operator confirms."""
    try:
        plan = app.engine.plan_resume()
    except StairbotError as exc:
        message = f"cannot resume: {exc}"
        app.state.set_status(message=message, severity="error")
        app.say(message, "error", timeout=10)
        return

    def answered(yes: bool | None) -> None:
        if yes:
            app.run_program(mode, plan)
        else:
            app.say("not resumed: nothing moved")

    lines = "\n".join(plan.lines)
    app.push_screen(MotionConfirm(
        f"Resume on {plan.state.start.get('url')}:\n{lines}\n\nLook at the robot: does "
        "it stand where these lines say?  Resume and let it move?  Space stops every "
        "motor.", yes="Resume"), answered)


def pause(app: StairbotConsole) -> None:
    """Hold the run where it is, or let it move on (on a wire, once the
    operator consents)."""
    if not app.engine.running:
        app.say("no run is going on")
    elif app.state.view().status.paused:
        after_consent(app, "Resume motion", app.engine.resume)
    else:
        app.engine.pause()
    app.refresh_view()


def after_consent(app: StairbotConsole, what: str, go: Callable[[], object]) -> None:
    """Do ``go`` now for the in-process simulation; for a robot on a wire ask
    first.  Fake boards are asked about too: that they are simulated is only
    their own word (a status flag), which is no ground for moving unasked."""
    session = app.engine.session
    if session is None or app.engine.in_process:
        go()
        return
    boards = ("Boards on a wire that report a simulated world (fake boards)."
              if session.simulated else "REAL boards on a wire.")

    def answered(yes: bool | None) -> None:
        if yes:
            go()
            app.refresh_view()
        else:
            app.say("nothing moved")

    app.push_screen(MotionConfirm(
        f"{what} on {session.url}?\n{boards}\n"
        "The motors will move. Space stops every motor.", yes=what), answered)


def quit_console(app: StairbotConsole, key: str = "q") -> None:
    """Quit; mid-run the robot stops first (the emergency stop, latched),
    then the console asks: the answer may take a while, and the robot must
    not drive on meanwhile."""
    if not app.engine.running:
        app.exit()
        return
    if not app.engine.latched:
        app.engine.estop(f"{key} pressed mid-run")
        app.refresh_view()
    if app.asking_quit:
        return
    app.asking_quit = True

    def answered(yes: bool | None) -> None:
        app.asking_quit = False
        if yes:
            app.exit()  # on_unmount ends the run and releases the robot
        else:
            app.say("not quitting: the run is held, EMERGENCY STOP latched "
                    "(c clears it, then p resumes)", "warning")

    app.push_screen(ConfirmScreen(
        "The robot is stopped: EMERGENCY STOP latched (every motor stopped, the lifts "
        "hold).\nQuit the console? The run ends; the robot stays where it stands, "
        "latched.", yes="Yes, quit (y)", no="No, stay (n)"), answered)
