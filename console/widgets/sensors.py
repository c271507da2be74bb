"""The four distance sensors: value and status, and whether each pair that
must agree (SFR/SFL, SBR/SBL) agrees within ``equal_tolerance``."""

from __future__ import annotations

from rich.text import Text
from textual.widgets import Static

from stairbot.hardware import SensorId, SensorReading, SensorStatus, Snapshot

PAIRS = (("front", SensorId.SFR, SensorId.SFL), ("back", SensorId.SBR, SensorId.SBL))


def _reading(name: str, r: SensorReading | None) -> Text:
    line = Text(f"{name} ", style="bold")
    if r is None:
        line.append("    —        no reading", "dim")
    elif r.status is SensorStatus.OK:
        line.append(f"{r.distance_m:7.3f} m  ok", "green")
    elif r.status is SensorStatus.OUT_OF_RANGE:
        line.append(f"{r.distance_m:7.3f} m  out of range", "yellow")
    else:
        line.append("  error      ", "bold red")
        line.append("sensor fault", "red")
    return line


def pair_text(label: str, a: SensorReading | None, b: SensorReading | None,
              tolerance: float) -> Text:
    """``front agree Δ 1 mm`` / ``front DIFFER Δ 12 mm`` / ``front no pair``."""
    line = Text(f"{label:<5} ", style="bold")
    if a is None or b is None or not a.ok or not b.ok:
        both_far = (a is not None and b is not None
                    and a.status is SensorStatus.OUT_OF_RANGE
                    and b.status is SensorStatus.OUT_OF_RANGE)
        line.append("both out of range" if both_far else "cannot compare", "yellow")
        return line
    delta = abs(a.distance_m - b.distance_m)
    if delta <= tolerance:
        line.append("agree  ", "bold green")
    else:
        line.append("DIFFER ", "bold white on red")
    line.append(f"Δ {delta * 1000:.0f} mm (tol {tolerance * 1000:.0f})", "dim")
    return line


class SensorPanel(Static):
    """Four sensor lines and two agreement lines."""

    DEFAULT_CSS = "SensorPanel { height: auto; }"

    def __init__(self, tolerance: float, *, id: str | None = None) -> None:  # noqa: A002
        super().__init__(id=id)
        self.tolerance = tolerance
        self._last: object = ()
        self.border_title = "sensors"

    def show(self, snap: Snapshot | None) -> None:
        sensors = dict(snap.sensors) if snap is not None else {}
        if sensors == self._last:
            return
        self._last = sensors
        lines = []
        for label, a, b in PAIRS:
            lines.append(_reading(a.value, sensors.get(a)))
            lines.append(_reading(b.value, sensors.get(b)))
            lines.append(pair_text(label, sensors.get(a), sensors.get(b), self.tolerance))
        self.update(Text("\n").join(lines))
