"""The four distance sensors: value and status, and whether each pair that
must agree (SFR/SFL, SBR/SBL) agrees within ``equal_tolerance``.

Four lines, a bracket joining each pair to its verdict: two lines fewer than a
verdict line per pair, which an 80x24 screen needs for the panels below.
"""

from __future__ import annotations

from rich.text import Text
from textual.widgets import Static

from stairbot.hardware import SensorId, SensorReading, SensorStatus, Snapshot

PAIRS = ((SensorId.SFR, SensorId.SFL), (SensorId.SBR, SensorId.SBL))
READING_WIDTH = 26  # "SFR  1.234 m  out of range"


def _reading(name: str, r: SensorReading | None) -> Text:
    line = Text(f"{name} ", style="bold")
    if r is None:
        line.append("    —     no reading", "dim")
    elif r.status is SensorStatus.OK:
        line.append(f"{r.distance_m:6.3f} m  ok", "green")
    elif r.status is SensorStatus.OUT_OF_RANGE:
        line.append(f"{r.distance_m:6.3f} m  out of range", "yellow")
    else:
        line.append("    —     ", "dim")
        line.append("sensor error", "bold red")
    line.pad_right(READING_WIDTH - line.cell_len)
    return line


def pair_verdict(a: SensorReading | None, b: SensorReading | None,
                 tolerance: float) -> tuple[Text, Text]:
    """Two short texts, beside each sensor of a pair: ``agree`` / ``Δ 1 mm``,
    ``DIFFER`` / ``Δ 12 mm``, ``both out`` / ``of range``, ``cannot`` / ``compare``."""
    if a is None or b is None or not a.ok or not b.ok:
        if (a is not None and b is not None and a.status is SensorStatus.OUT_OF_RANGE
                and b.status is SensorStatus.OUT_OF_RANGE):
            return Text("both out", "yellow"), Text("of range", "yellow")
        return Text("cannot", "yellow"), Text("compare", "yellow")
    delta_mm = abs(a.distance_m - b.distance_m) * 1000
    delta = Text(f"Δ {delta_mm:.0f} mm" if delta_mm < 99.5 else "Δ>99 mm", "dim")
    if delta_mm <= tolerance * 1000:
        return Text("agree", "bold green"), delta
    return Text("DIFFER", "bold white on red"), delta


class SensorPanel(Static):
    """Four sensor lines; each pair bracketed with its verdict."""

    DEFAULT_CSS = "SensorPanel { height: auto; }"

    def __init__(self, tolerance: float, *, id: str | None = None) -> None:  # noqa: A002
        super().__init__(id=id)
        self.tolerance = tolerance
        self._last: object = ()
        self.border_title = f"sensors  pairs agree within {tolerance * 1000:.0f} mm"

    def show(self, snap: Snapshot | None) -> None:
        sensors = dict(snap.sensors) if snap is not None else {}
        if sensors == self._last:
            return
        self._last = sensors
        lines = []
        for a, b in PAIRS:
            top, bottom = pair_verdict(sensors.get(a), sensors.get(b), self.tolerance)
            for sensor, bracket, verdict in ((a, " ┐ ", top), (b, " ┘ ", bottom)):
                line = _reading(sensor.value, sensors.get(sensor))
                line.append(bracket, "dim")
                line.append_text(verdict)
                lines.append(line)
        self.update(Text("\n").join(lines))
