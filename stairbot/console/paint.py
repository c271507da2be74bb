"""What the console's screen shows of the live state: which of the side
view, the top view and the graphs have room (by the screen's height and the
operator's choices: :func:`lay_out`), and what every panel draws from one
copy of the state (:func:`show`).  Each function takes the console app whose
panels it fills (:class:`~stairbot.console.app.StairbotConsole`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from rich.text import Text

from stairbot.console.freshness import age_words, is_stale
from stairbot.console.limp_gate import limping_words
from stairbot.console.roomy import message_rows
from stairbot.console.state import StateView
from stairbot.console.widgets.banner import MESSAGE_LINES, liveness
from stairbot.console.words import carried_by
from stairbot.hardware import MotorId
from stairbot.views.reckon import dead_reckon

if TYPE_CHECKING:
    from stairbot.console.app import StairbotConsole

GRAPHS_ROWS = 36
"""From this many rows the graphs show under the picture; on a smaller
screen they take the picture's place while the operator wants them (g)."""


def tall(app: StairbotConsole, rows: int | None = None) -> bool:
    """Whether the screen (``rows`` high, None: the app's height) has room
    for the graphs under the picture."""
    return (app.size.height if rows is None else rows) >= GRAPHS_ROWS


MIN_COLUMNS, MIN_ROWS = 80, 24
"""The smallest screen the panels fit: on a smaller one they give way to a
notice that says so (a cut panel would hide a status, a speed, a key)."""


def too_small(columns: int, rows: int) -> str:
    """What the notice says on a ``columns`` x ``rows`` screen ("": it fits)."""
    if columns >= MIN_COLUMNS and rows >= MIN_ROWS:
        return ""
    return (f"The terminal is too small: {columns}x{rows}; the console needs "
            f"{MIN_COLUMNS}x{MIN_ROWS}.  Make it larger to see the robot.\n"
            "space: EMERGENCY STOP (every motor, now)   q: quit   x: stop the run")


def lay_out(app: StairbotConsole, rows: int | None = None,
            columns: int | None = None) -> None:
    """Show the graphs under the picture on a tall screen (``rows``: its
    height, None: the app's); on a smaller one in the picture's place,
    and only while the operator wants them.  Below MIN_COLUMNS x MIN_ROWS
    (``columns``: its width, None: the app's) the panels give way to the
    too-small notice."""
    small = too_small(app.size.width if columns is None else columns,
                      app.size.height if rows is None else rows)
    app.main_area.display = not small
    app.small_notice.display = bool(small)
    app.small_notice.update(small)
    is_tall = tall(app, rows)
    app.screen_rows = rows if rows is not None else app.size.height
    wanted = is_tall if app.graphs is None else app.graphs
    app.trends.display = wanted and not app.plotting.picked
    app.plotting.panel.display = wanted and bool(app.plotting.picked)  # v: in their place
    picture = is_tall or not wanted
    app.picture.display = picture and not app.top_shown
    app.top_view.display = picture and app.top_shown
    if wanted:
        app.shown_key = None  # draw them now


def show(app: StairbotConsole, v: StateView) -> None:
    """Every panel, from ``v`` (a copy of the live state)."""
    age = v.read_age_s
    # the right column stays whole (a fault's reason keeps two lines)
    app.banner.room = message_rows(app, MESSAGE_LINES, fault=v.status.robot == "fault")
    app.banner.show(v.url, v.scenario, v.status, v.recording,
                    limping_words(v.limping) if v.limping else "",
                    "" if app.replaying else liveness(age, v.status), v.boards,
                    replay=app.replaying, watching=bool(v.watching))
    picture = app.picture
    # never markup: the URL may hold brackets; with a landing, the frame it is in
    framed = v.top.flight if v.top is not None and v.plan and v.plan.landing else None
    title = Text("side view · " if framed is None else f"side view, flight {framed} · ")
    title.append(age_words(age), "bold red" if is_stale(age) else "dim")
    title.append(f" · {v.url} · {v.scenario}")
    picture.border_title = title
    picture.set_class(is_stale(age), "-stale")
    snap = v.snapshot
    lifts = None
    if snap is not None and MotorId.MTF in snap.motors and MotorId.MTB in snap.motors:
        per_turn = app.engine.config.motors.lift_travel_per_turn
        lifts = (snap.turns(MotorId.MTF) * per_turn, snap.turns(MotorId.MTB) * per_turn)
    scene, note = v.scene, app.picture_note() if v.scene is None else ""
    if v.wired and scene is None and not app.replaying:
        scenario = app.engine.scenario
        if snap is not None and v.stairs and scenario is not None:
            scene = dead_reckon(snap, v.stairs, app.engine.config, scenario.start.distance)
            note = "dead-reckoned (wired robot)"
        else:
            note = "no pose from a wired robot"
    picture.show(scene, v.stairs, lifts, note)
    show_top(app, v)
    running = v.status.robot in ("running", "replay")  # a replay: the recorded phase
    app.sensors.show(snap, age, v.limping)
    app.motors.show(snap, v.commands, age, carried_by(v.phase_id) if running else ())
    app.phase.show(v.phase, v.flow, v.context, v.phase_id, degraded=degraded_title(v))
    app.link.show(not v.wired, snap.time_s if snap else None, v.speed, v.health, age,
                  replay=app.replaying)
    if app.trends.display:
        app.trends.show(v.history, age)
    app.plotting.follow(app, v)
    if v.events:
        log = app.log_panel
        log.add(v.events)
        app.shown_event = log.last_seq


def degraded_title(v: StateView) -> str:
    """The phase panel's word for a run that limps home: while it does, and
    how it ended ("": it does not)."""
    if not v.limping:
        return ""
    if not v.limp_end:
        return "LIMPING HOME"
    return "CAME HOME DEGRADED" if v.limp_end == "came_home_degraded" else "DEGRADED"


def show_top(app: StairbotConsole, v: StateView) -> None:
    """The top view, and a wall contact told once in the event list (the
    side view cannot show it)."""
    top, age, note = app.top_view, v.top_age_s, app.top_note(v)
    stale = not note and is_stale(age)
    title = Text("top view · ")
    if note:
        title.append("none", "dim")
    else:
        title.append(age_words(age), "bold red" if stale else "dim")
    title.append(f" · {v.url} · {v.scenario}")
    top.border_title = title
    top.set_class(stale, "-stale")
    top.show(None if note else v.plan, None if note else v.top, app.robot_shape, note, stale)
    if v.top is None:
        return
    contact = v.top.wall_contact
    if contact and contact != app.contact_said:
        app.say(f"wall contact: {contact} (t: the top view)", "warning", timeout=10)
    app.contact_said = contact  # a new robot's pose has none: the next is told
