"""The plot of the signals the operator picked (key ``v``): up to four, over
the last seconds of robot time, drawn by ``textual-plotext``'s
``PlotextPlot`` in the graphs' place, the first unit on the left axis and
the second on the right.  A legend line above names each signal with its
unit and latest value, in its line's colour.

Nothing is drawn past the last reading: a signal whose readings stopped
ends where they stopped.  Once the readings are older than
:data:`~stairbot.console.freshness.STALE_S` (or a sensor has not measured
for that long) the legend says STALE for that signal, its line turns grey,
and when the whole reading is stale the panel is dimmed and its title says
STALE, as every panel of robot values does.

In a replay a timeline stands under the plot: the whole recording, its
errors, pauses and phase changes marked (console/markers.py), the position
on it.

plotext draws the plot into text on the UI thread, and that costs tens of
milliseconds on a large terminal (``python benchmarks/bench_console_plot.py``),
time the UI thread does not spend elsewhere.  So the lines are drawn at most
once a :meth:`PlotPanel.period_for` of the measured cost of the last
redraw: :data:`PLOT_SHARE` of the UI thread at most, never more often than
every :data:`MIN_PERIOD_S`.  The legend and the title (the values, STALE)
follow every reading at once: they cost little.  A hidden panel draws
nothing (console/plotting.py does not hand it readings)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence

from rich.text import Text
from textual.app import ComposeResult, RenderResult
from textual.containers import Vertical
from textual.widgets import Static
from textual_plotext import PlotextPlot

from stairbot.console.freshness import age_key, is_stale, titled
from stairbot.console.markers import Marker, step, timeline
from stairbot.console.signals import Reading, Series, Signal, series, thin, units_of

COLOURS: tuple[tuple[int, int, int], ...] = (
    (0, 200, 220), (255, 150, 0), (220, 80, 220), (90, 210, 90))
"""Each picked signal's line and legend colour, in the order picked."""
STALE_COLOUR = (128, 128, 128)
PLOT_SHARE = 0.1
"""The largest share of the UI thread's time the plot's redraws may take."""
MIN_PERIOD_S = 0.25
"""The lines are redrawn at most this often (4 a second), however cheap."""
MAX_PERIOD_S = 2.0
"""...and at least this often while readings come, however dear."""
CATCH_UP_S = 0.1
"""How often the panel looks whether lines held back by the throttle are due."""
DIGITS = {"m": 3, "mm": 0, "°": 1, "°/s": 1, "turn/s": 2, "turns": 2, "ms": 1,
          "frames/s": 0, "count": 0}


def value_words(value: float | None, unit: str) -> str:
    """``0.204 m``, ``ERROR`` (a reading with no number), ``—`` (none)."""
    if value is None:
        return "—"
    if math.isnan(value):
        return "ERROR"
    return f"{value:.{DIGITS.get(unit, 2)}f}{'' if unit == '°' else ' '}{unit}"


class TimedPlot(PlotextPlot):
    """plotext's widget, counting its builds and timing the last one in CPU
    time of the thread that draws (the UI thread)."""

    def __init__(self, *, id: str | None = None) -> None:  # noqa: A002
        super().__init__(id=id)
        self.builds = 0
        """How many times plotext drew the plot into text."""
        self.build_s = 0.0
        """What the last build cost (CPU seconds of the UI thread)."""

    def render(self) -> RenderResult:
        start = time.thread_time()
        out = super().render()
        self.builds += 1
        self.build_s = time.thread_time() - start
        return out


class PlotPanel(Vertical):
    """The legend, the plot, and (replaying) the timeline with its markers."""

    DEFAULT_CSS = """
    PlotPanel {
        height: 3fr; min-height: 8;
        border-top: solid $primary; border-title-color: $text-accent; padding: 0 0 0 1;
    }
    PlotPanel .plot-legend { height: auto; }
    PlotPanel PlotextPlot { height: 1fr; }
    PlotPanel .plot-timeline { height: 2; display: none; }
    """

    def __init__(self, *, id: str | None = None,  # noqa: A002
                 clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__(id=id)
        self.clock = clock
        """The clock the throttle goes by (seconds; a test moves its own)."""
        self.border_title = titled("plots", None)
        self.legend = Static("", classes="plot-legend", markup=False)
        self.plot = TimedPlot(id="plot")
        self.timeline = Static("", classes="plot-timeline", markup=False)
        self.shown: tuple[Series, ...] = ()
        """The signals' series as last shown, for the legend (and tests)."""
        self.drawn: list[tuple[list[float], list[float]]] = []
        """What plotext was last handed, each series thinned to what the
        plot's width shows (:func:`~stairbot.console.signals.thin`)."""
        self.plain_legend = ""
        self.plain_timeline = ""
        self._last: object = None
        self.draws = 0
        """How many times the lines were handed to plotext (each a build)."""
        self.drawn_at: float | None = None
        """When (:attr:`clock`) the lines were last handed over (None: not yet)."""
        self.show_s = 0.0
        """What the last handover cost (CPU seconds)."""
        self._owed: Sequence[Reading] | None = None
        """Readings the throttle held back: drawn once :meth:`due`."""

    def on_mount(self) -> None:
        self.set_interval(CATCH_UP_S, self._catch_up)

    @staticmethod
    def period_for(cost_s: float) -> float:
        """The least time between two redraws that cost ``cost_s`` each, so
        they take at most PLOT_SHARE of the UI thread."""
        return min(max(cost_s / PLOT_SHARE, MIN_PERIOD_S), MAX_PERIOD_S)

    @property
    def period_s(self) -> float:
        """The throttle's period now, by what the last redraw cost."""
        return self.period_for(self.show_s + self.plot.build_s)

    def due(self) -> bool:
        """Whether the lines may be drawn again now."""
        return self.drawn_at is None or self.clock() - self.drawn_at >= self.period_s

    def _catch_up(self) -> None:
        if self._owed is not None and self.display and self.due():
            self._draw(self._owed)

    def compose(self) -> ComposeResult:
        yield self.legend
        yield self.plot
        yield self.timeline

    def redraw(self) -> None:
        """Draw at the next :meth:`show`, even if nothing changed, and the
        lines at once (new signals picked)."""
        self._last = None
        self.drawn_at = None

    def show(self, picked: Sequence[Signal], readings: Sequence[Reading],
             read_age_s: float | None) -> None:
        """Draw ``picked`` over ``readings``; ``read_age_s``: how old the
        latest reading is (None: never read)."""
        key = (tuple(s.key for s in picked), readings[-1][0] if readings else None,
               len(readings), age_key(read_age_s))
        if key == self._last:
            return
        self._last = key
        stale = is_stale(read_age_s)
        span = readings[-1][0] - readings[0][0] if len(readings) > 1 else 0.0
        self.border_title = titled(f"plots · last {span:.0f} s", read_age_s)
        self.set_class(stale, "-stale")
        self.shown = tuple(series(s, readings, read_age_s) for s in picked)
        self._legend()
        if self.due():
            self._draw(readings)
        else:
            self._owed = readings

    def _legend(self) -> None:
        """One entry a signal, as many a line as the width holds (an entry is
        never broken)."""
        width = self.legend.size.width or self.size.width - 1
        lines: list[Text] = [Text(no_wrap=True, overflow="ellipsis")]
        for i, s in enumerate(self.shown):
            colour = "rgb({},{},{})".format(*(STALE_COLOUR if s.stale else COLOURS[i]))
            entry = Text("━ ", colour)
            entry.append(f"{s.signal.brief} ", "bold")
            entry.append(value_words(s.last, s.signal.unit),
                         "dim" if s.stale else "bold red" if s.last is not None
                         and math.isnan(s.last) else "")
            if s.stale:
                entry.append(" STALE", "bold red")
            line = lines[-1]
            if line.plain and width > 0 and len(line) + 2 + len(entry) > width:
                lines.append(Text(no_wrap=True, overflow="ellipsis"))
                line = lines[-1]
            if line.plain:
                line.append("  ")
            line.append_text(entry)
        out = Text("\n").join(lines)
        self.legend.update(out)
        self.plain_legend = out.plain

    def _draw(self, readings: Sequence[Reading]) -> None:
        """Hand the lines to plotext (it draws them at the next refresh)."""
        start = time.thread_time()
        self._owed = None
        self.drawn_at = self.clock()
        self.draws += 1
        plt = self.plot.plt
        plt.clear_data()
        units = units_of(s.signal for s in self.shown)
        self.drawn = [([], []) for _ in self.shown]
        for i, s in enumerate(self.shown):
            if not s.xs:
                continue
            side = "left" if s.signal.unit == units[0] else "right"
            xs, ys = thin(s.xs, s.ys, max(self.plot.size.width // 2, 10))  # a point a column
            self.drawn[i] = (xs, ys)
            plt.plot(xs, ys, yside=side, marker="braille",
                     color=STALE_COLOUR if s.stale else COLOURS[i])
        # the side positionally: textual-plotext's stub names it ``xside``
        plt.ylabel(units[0] if units else "", "left")
        plt.ylabel(units[1] if len(units) > 1 else "", "right")
        plt.xlabel("robot time (s)")
        if readings:  # the axis ends at the last reading, never at "now"
            first, last = readings[0][0], readings[-1][0]
            plt.xlim(first, last if last > first else first + 1.0)
        self.plot.refresh()
        self.show_s = time.thread_time() - start

    def show_timeline(self, markers: Sequence[Marker], start_s: float, end_s: float,
                      position: float) -> None:
        """The recording from ``start_s`` to ``end_s``, its ``markers``, and
        the ``position``; under it the markers before and after it."""
        self.timeline.display = True
        width = max(self.timeline.size.width or self.size.width - 1, 10)
        line = timeline(markers, start_s, end_s, position, width)
        before, after = step(markers, position, -1), step(markers, position, +1)
        here = [m for m in markers if abs(m.time_s - position) < 1e-6]
        words = Text(f"{len(markers)} markers (keys , .)", "dim")
        if here:
            words.append(f" · here {here[-1].line()}")
        elif after is not None:
            words.append(f" · next {after.line()}")
        elif before is not None:
            words.append(f" · last {before.line()}")
        shown = Text("\n", no_wrap=True, overflow="ellipsis").join([line, words])
        self.timeline.update(shown)
        self.plain_timeline = f"{line.plain}\n{words.plain}"
