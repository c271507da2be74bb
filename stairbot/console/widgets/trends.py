"""The graphs (key ``g``): the IMU's pitch, the distance sensors (the side
pair too, on a robot that has it) and the two lifts over the last seconds
of robot time, one Textual ``Sparkline``
each, the latest value before it and the range drawn after it (each line
scales to its own range: the range says how much a swing is).

They advance with the robot's clock, not the wall's: when the readings stop,
so do they, and once the readings are older than
:data:`~stairbot.console.freshness.STALE_S` the panel is dimmed and its
title says STALE, as every panel of robot values does."""

from __future__ import annotations

import math
from collections.abc import Sequence

from rich.text import Text
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.widgets import Sparkline, Static

from stairbot.console.freshness import age_key, is_stale, titled
from stairbot.console.history import NOT_CARRIED, Row, column, series
from stairbot.console.widgets.sensors import NAMES as SENSOR_NAMES
from stairbot.hardware import SensorId

LABEL_WIDTH = 14  # "front R  0.204"
RANGE_WIDTH = 12  # "0.041…1.300"


def _signed(value: float, digits: int) -> str:
    """``+1.5``, ``-0.2``, ``+0`` (never ``-0``: a value that rounds to 0)."""
    shown = round(value, digits) + 0.0  # + 0.0 makes -0.0 plain 0.0
    return f"{shown:+.{digits}f}"


def _mean(values: Sequence[float]) -> float:
    return sum(values) / len(values)


def _label(name: str) -> str:
    if name == "pitch":
        return "pitch"
    if name in SensorId.__members__:
        return SENSOR_NAMES[SensorId(name)]
    return name


class TrendsPanel(Vertical):
    """One line a series: ``name value``, its sparkline, ``low…high``."""

    DEFAULT_CSS = """
    TrendsPanel { height: auto; }
    TrendsPanel > Horizontal { height: 1; }
    TrendsPanel .trend-label { width: 14; }
    TrendsPanel .trend-range { width: 12; padding-left: 1; color: $text-muted; }
    TrendsPanel Sparkline { width: 1fr; }
    """

    def __init__(self, lift_m_per_turn: float, *, side_pair: bool = False,
                 id: str | None = None) -> None:  # noqa: A002
        """``side_pair``: the robot has SSR/SSL (its config's ``[sensors]
        side_model``): a line each for them too."""
        super().__init__(id=id)
        self.lift_m_per_turn = lift_m_per_turn
        self.series = series(side_pair)
        self._last: object = None
        self.border_title = titled("graphs", None)
        self.labels = {name: Static("", classes="trend-label", markup=False)
                       for name in self.series}
        self.ranges = {name: Static("", classes="trend-range", markup=False)
                       for name in self.series}
        self.lines = {name: Sparkline([], summary_function=_mean, id=f"trend-{name}")
                      for name in self.series}
        self.plain: dict[str, str] = {}  # each line's label and range as shown, for tests

    def compose(self) -> ComposeResult:
        for name in self.series:
            with Horizontal():
                yield self.labels[name]
                yield self.lines[name]
                yield self.ranges[name]

    def show(self, rows: Sequence[Row], age_s: float | None) -> None:
        """Draw ``rows`` (console/history.py); ``age_s``: how old the last
        reading is (None: never read)."""
        key = (rows[-1][0] if rows else None, len(rows), age_key(age_s))
        if key == self._last:
            return
        self._last = key
        span = rows[-1][0] - rows[0][0] if len(rows) > 1 else 0.0
        self.border_title = titled(f"graphs · last {span:.0f} s", age_s)
        self.set_class(is_stale(age_s), "-stale")
        for name in self.series:
            i = column(name)
            values = [r[i] for r in rows if math.isfinite(r[i])]
            last = rows[-1][i] if rows else NOT_CARRIED  # never read: no value, no error
            label, low, high = self._texts(name, last, values)
            self.labels[name].update(label)
            self.ranges[name].update(Text(f"{low}…{high}" if values else ""))
            self.plain[name] = f"{label.plain} | {low}…{high}" if values else label.plain
            # one point would fill the line (the widget draws it full height): a
            # line needs two to say anything
            self.lines[name].data = values if len(values) > 1 else []

    def _texts(self, name: str, last: float, values: list[float]) -> tuple[Text, str, str]:
        out = Text(f"{_label(name):<8}", style="bold", no_wrap=True, overflow="ellipsis")
        low = min(values) if values else math.nan
        high = max(values) if values else math.nan
        if name == "pitch":
            value = "—" if not math.isfinite(last) else f"{_signed(last, 1)}°"
            lo, hi = _signed(low, 1), f"{_signed(high, 1)}°"
        elif name in SensorId.__members__:
            value = ("—" if last == NOT_CARRIED  # no such reading (a side sensor not read)
                     else "ERROR" if math.isnan(last) else f"{last:.3f}")
            lo, hi = f"{low:.3f}", f"{high:.3f}"
        else:  # a lift: turns as the extension, mm
            mm = 1000 * self.lift_m_per_turn
            value = "—" if not math.isfinite(last) else f"{_signed(last * mm, 0)}mm"
            lo, hi = _signed(low * mm, 0), _signed(high * mm, 0)
        out.append(value.rjust(LABEL_WIDTH - 8), "bold red" if value == "ERROR" else "")
        return out, lo, hi
