"""The plots of any signal (key ``v``) in a console: which signals the
operator picked, the readings they are drawn over, and, replaying, the
recording's markers and the jumps between them (``,`` and ``.``).

Live, the plot is drawn over every reading of the graphs' window as the
live state keeps it (console/history.py: one a reading, newer than the
last, by the robot's clock), at the screen's refresh; so it has no point
the robot did not give.  Watching another console's robot, over the
readings the screen copies, one a refresh (:class:`~stairbot.console.
signals.Samples`).  Replaying, over the recording's own ticks in the window
up to the position, on the replay's timeline (the markers' and the
position's): every tick, whatever the replay's speed, and a seek back
draws at once what was there.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from stairbot.console.history import WINDOW_S
from stairbot.console.markers import Marker, markers_of, step
from stairbot.console.paint import lay_out
from stairbot.console.plot_picker import PlotPicker
from stairbot.console.signals import Reading, Samples, Signal, by_key, catalogue
from stairbot.console.state import StateView
from stairbot.console.widgets.plots import PlotPanel

if TYPE_CHECKING:
    from stairbot.console.app import StairbotConsole
    from stairbot.console.replay import ReplayPlayer


class Plotting:
    """A console's plot: its panel, the signals picked, what they are drawn over."""

    def __init__(self) -> None:
        self.panel = PlotPanel(id="plots")
        self.picked: tuple[Signal, ...] = ()
        """The signals plotted, in the order picked (empty: the graphs); each
        read out of every reading, those that no longer carry it too."""
        self.samples = Samples()
        """Watching another console's robot: its readings as the screen
        copies them, one a refresh (the watched console keeps every one)."""
        self.watching = False
        self.player: ReplayPlayer | None = None
        self.markers: tuple[Marker, ...] = ()

    def replay(self, player: ReplayPlayer) -> None:
        """Draw from ``player``'s recording, and mark its errors, pauses and phases."""
        self.player = player
        self.markers = markers_of(player.source.events)

    def readings(self, app: StairbotConsole) -> tuple[Reading, ...]:
        """What the plot is drawn over: the readings of the window."""
        player = self.player
        if player is None:
            if self.watching:
                return self.samples.readings()
            return tuple((s.time_s, s) for s in app.state.readings())
        src = player.source
        first = src.tick_index(player.position - WINDOW_S)
        return tuple((t.time_s, t.snapshot) for t in src.ticks[first:src.tick_index(
            player.position)] if t.snapshot is not None)

    def signals(self, app: StairbotConsole) -> tuple[Signal, ...]:
        """Every signal this console knows now (link figures once read)."""
        return catalogue((snap for _, snap in self.readings(app)),
                         app.engine.config.motors.lift_travel_per_turn,
                         side_pair=app.engine.config.sensors.has_side_pair)

    def follow(self, app: StairbotConsole, v: StateView) -> None:
        """Keep ``v``'s reading, and draw the plot when it shows (paint.show)."""
        self.watching = bool(v.watching)
        if self.watching:
            self.samples.add(v.snapshot)
        else:
            self.samples.clear()
        if not self.panel.display:
            return
        self.panel.show(self.picked, self.readings(app), v.read_age_s)
        if self.player is not None:
            player = self.player
            self.panel.show_timeline(self.markers, player.start_s, player.end_s,
                                     player.position)


def pick(app: StairbotConsole) -> None:
    """``v``: the picker; what is picked is plotted in the graphs' place."""
    p = app.plotting
    if isinstance(app.screen, PlotPicker):
        return

    def picked(keys: tuple[str, ...] | None) -> None:
        if keys is None:
            return
        plot(app, keys)

    known = p.signals(app)
    gone = tuple(s for s in p.picked if s.key not in by_key(known))  # not carried now
    app.push_screen(PlotPicker(known + gone, [s.key for s in p.picked]), picked)


def plot(app: StairbotConsole, keys: Sequence[str]) -> None:
    """Plot the signals ``keys`` (none: the graphs again), shown now on any screen."""
    p = app.plotting
    known = by_key(p.signals(app) + p.picked)
    p.picked = tuple(known[k] for k in keys if k in known)
    p.panel.redraw()
    if p.picked:
        app.graphs = True
        app.say("plotting " + ", ".join(s.name for s in p.picked)
                + " (v: pick others, or none for the graphs; g: hide)", keep=False)
    else:
        app.say("the graphs again (v: plot signals)", keep=False)
    lay_out(app, app.screen_rows)
    app.shown_key = None
    app.refresh_view()


def jump(app: StairbotConsole, direction: int) -> None:
    """Replaying: to the next (``direction`` > 0) or previous marker."""
    p = app.plotting
    if p.player is None:
        return
    to = step(p.markers, p.player.position, direction)
    if to is None:
        where = "after" if direction > 0 else "before"
        app.say(f"no marker {where} t = {p.player.position:.1f} s "
                f"({len(p.markers)} in the recording)", keep=False)
        return
    p.player.seek(to.time_s)
    app.say(to.line(), keep=False)
