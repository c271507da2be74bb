"""Link health for a wired robot (frames per second, errors, round-trip time,
from ``Snapshot.health`` and the driver's link events); for a simulation the
simulated time, the speed and the control ticks."""

from __future__ import annotations

from collections.abc import Mapping

from rich.text import Text
from textual.widgets import Static

SPEED_NAMES = {"1x": "1×", "10x": "10×", "max": "max"}
# Health keys worth a short name; anything else is shown as it comes.
SHORT = {"frames_per_s": "fps", "rtt_ms": "rtt ms", "rtt_p99_ms": "rtt p99",
         "crc_errors": "crc err", "retries": "retries", "lost": "lost", "late": "late"}
ERROR_KEYS = ("crc_errors", "lost", "late", "errors", "timeouts")


def health_text(health: Mapping[str, float]) -> Text:
    out = Text()
    if not health:
        return Text("no link figures yet", "dim")
    for i, (key, value) in enumerate(sorted(health.items())):
        if i:
            out.append("  ")
        bad = key in ERROR_KEYS and value > 0
        out.append(f"{SHORT.get(key, key)} ", "dim")
        out.append(f"{value:g}" if abs(value) >= 100 or value == int(value) else f"{value:.2f}",
                   "bold red" if bad else "")
    return out


class LinkPanel(Static):
    """The link's health, or the simulation's clock and speed."""

    DEFAULT_CSS = "LinkPanel { height: auto; }"

    def __init__(self, *, id: str | None = None) -> None:  # noqa: A002
        super().__init__(id=id)
        self._last: object = None
        self.border_title = "link"

    def show(self, simulated: bool, time_s: float | None, ticks: int, speed: str,
             health: Mapping[str, float], recording: str | None) -> None:
        key = (simulated, None if time_s is None else round(time_s, 1), ticks // 5, speed,
               tuple(sorted(health.items())), recording)
        if key == self._last:
            return
        self._last = key
        if simulated:
            self.border_title = "simulation"
            out = Text("t ", "dim")
            out.append("—" if time_s is None else f"{time_s:7.1f} s")
            out.append("  speed ", "dim")
            out.append(SPEED_NAMES.get(speed, speed), "bold")
        else:
            self.border_title = "link health"
            out = health_text(health)
        out.append("\n")
        out.append("rec ", "dim")
        out.append(recording if recording else "off", "bold red" if recording else "dim")
        self.update(out)
