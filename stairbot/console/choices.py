"""The operator's choices that move nothing: which robot and scenario the
console opens, the simulation's speed, the record, and how the picture
shows (graphs, zoom, the top view).  Each function takes the console app
whose action it carries out (:class:`~stairbot.console.app.StairbotConsole`
binds the keys to them).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from stairbot.console import board_robot
from stairbot.console.connect_screen import ConnectScreen
from stairbot.console.modals import AskScreen, Notice
from stairbot.console.paint import lay_out, tall
from stairbot.console.robot_holder import SPEEDS
from stairbot.errors import InputError
from stairbot.inputs.schema import shipped

if TYPE_CHECKING:
    from stairbot.console.app import StairbotConsole

SPEED_ORDER = tuple(SPEEDS)


RUN_GOING_ON = ("A run is going on: {what} can be chosen once it has ended "
                "(x stops it).")


def choose_robot(app: StairbotConsole) -> None:
    if app.engine.running:
        app.push_screen(Notice(RUN_GOING_ON.format(what="another robot")))
        return

    def chosen(url: str | None) -> None:
        if url:  # fake boards of another robot: a question first
            board_robot.open_chosen(app, url, manager.listing)

    manager = ConnectScreen(app.url, sim_line(app))
    app.push_screen(manager, chosen)


def sim_line(app: StairbotConsole) -> str:
    """What ``sim://`` opens in this console: its robot (set at start: the
    panels are built for it) on the scenario ``o`` chooses."""
    robot = board_robot.robot_name(board_robot.own_config(app))
    return (f"{robot} robot, {app.scenario or 'default'} stairs (o: the stairs; "
            f"another robot: stairbot console --config {'|'.join(shipped('configs'))})")


def choose_scenario(app: StairbotConsole) -> None:
    if app.engine.running:
        app.push_screen(Notice(RUN_GOING_ON.format(what="another scenario")))
        return

    def chosen(name: str | None) -> None:
        if name is not None:
            app.open_robot(app.url, name or None)

    app.push_screen(AskScreen("Scenario file or shipped name (empty: default stairs)",
                              app.scenario or "", "default"), chosen)


def speed(app: StairbotConsole) -> None:
    if app.engine.session is not None and not app.engine.in_process:
        app.say("a robot on a wire keeps its own time (fake boards: --time-scale)",
                severity="warning")
        return
    current = app.state.view().speed
    nxt = SPEED_ORDER[(SPEED_ORDER.index(current) + 1) % len(SPEED_ORDER)]
    app.engine.set_speed(nxt)
    app.refresh_view()


def record(app: StairbotConsole) -> None:
    if app.engine.recorder is not None:
        path = app.engine.recorder.path
        app.engine.stop_recording()
        app.say(f"recording stopped: {path}")
        return

    def chosen(path: str | None) -> None:
        if path:
            start_recording(app, path)

    app.push_screen(AskScreen("Record to (FILE.mcap: every tick, MCAP; else the events, "
                              "JSON lines)", "events.jsonl"), chosen)


def start_recording(app: StairbotConsole, path: str) -> None:
    """Record to ``path``, or beside it when a file is there (never over it)."""
    try:
        chosen = app.engine.start_recording(path)
    except InputError as exc:
        app.say(str(exc), "error", timeout=8)
        return
    if chosen != path:
        app.say(f"{path} exists (not overwritten): recording to {chosen}",
                "warning", timeout=8)
    else:
        app.say(f"recording to {chosen}")


def graphs(app: StairbotConsole) -> None:
    is_tall = tall(app, app.screen_rows)
    app.graphs = not (is_tall if app.graphs is None else app.graphs)
    lay_out(app, app.screen_rows)
    where = "under the picture" if is_tall else "in place of the picture (g: the picture)"
    app.say(f"graphs {'shown ' + where if app.graphs else 'hidden'}", keep=False)
    app.refresh_view()


def zoom(app: StairbotConsole) -> None:
    if app.top_shown:
        mode = app.top_view.cycle_zoom()
        names = {"auto": "auto zoom", "flight": "the whole stairwell",
                 "robot": "following the robot"}
        app.say(f"top view: {names[mode]}", keep=False)
        return
    mode = app.picture.cycle_zoom()
    names = {"auto": "auto zoom", "flight": "whole flight", "robot": "following the robot"}
    app.say(f"picture: {names[mode]}", keep=False)


def top_view(app: StairbotConsole) -> None:
    """The picture between the side view and the top view; on a small screen
    it also comes back in the graphs' place."""
    app.top_shown = not app.top_shown
    if not tall(app, app.screen_rows) and app.graphs:
        app.graphs = False
    lay_out(app, app.screen_rows)
    app.say("picture: top view (t: the side view)" if app.top_shown
            else "picture: side view (t: the top view)", keep=False)
    app.shown_key = None
    app.refresh_view()


def event_filter(app: StairbotConsole) -> None:
    """``e``: the event list's next filter (every event, errors, warnings,
    phases, the link's)."""
    kinds = app.log_panel.next_filter()
    app.notify(f"events: {kinds}" if kinds == "all" else f"events: {kinds} only",
               timeout=2, markup=False)


def event_search(app: StairbotConsole) -> None:
    """``/``: list only the events whose text holds what is typed (empty: all)."""
    def chosen(text: str | None) -> None:
        if text is not None:
            app.log_panel.set_filter(search=text)

    app.push_screen(AskScreen("Search the events", app.log_panel.search, "lift",
                              "only the events whose text holds it (any case); "
                              "empty: every event"), chosen)
