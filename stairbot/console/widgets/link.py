"""Link health for a wired robot (frames per second, round-trip times, errors,
from ``Snapshot.health`` and the driver's LINK events); for a simulation the
simulated time and the speed."""

from __future__ import annotations

from collections.abc import Mapping

from rich.console import Group
from rich.text import Text
from textual.widgets import Static

from stairbot.console.freshness import age_key, is_stale, titled, without_status

SPEED_NAMES = {"1x": "1×", "10x": "10×", "max": "max"}
ERROR_KEYS = ("crc_errors", "malformed", "stray", "error_frames")
BUS_STATES = {1.0: "bus passive", 2.0: "BUS-OFF"}  # the CAN link's bus_state


def _figure(out: Text, label: str, value: float | None, unit: str = "",
            bad: bool = False) -> None:
    out.append(f"{label} ", "dim")
    if value is None:
        out.append("—")
    else:
        text = f"{value:.0f}" if value == int(value) or abs(value) >= 100 else f"{value:.2f}"
        out.append(text + unit, "bold red" if bad else "")
    out.append("  ")


def health_text(health: Mapping[str, float]) -> tuple[Text, Text]:
    """Two lines: frames per second and round-trip times; errors (stray
    replies among them), lost and late replies, retries (red when not zero),
    and duplicated replies when there were any (ignored, so not red); on
    CAN a bus that is not error-active, and the id of a flood, in red, at
    the head of the line: the right column at 80x24 is 39 characters wide
    and cuts the line's end."""
    if not health:
        return Text("no link figures yet  ", "dim"), Text()
    rates = Text(no_wrap=True, overflow="ellipsis")
    _figure(rates, "fps", health.get("frames_per_s"))
    med = health.get("rtt_median_ms", health.get("rtt_ms"))
    p99 = health.get("rtt_p99_ms")
    rates.append("rtt/p99 ", "dim")
    rates.append("—" if med is None else f"{med:.2f}")
    rates.append("/" + ("—" if p99 is None else f"{p99:.2f}") + " ms  ")
    faults = Text(no_wrap=True, overflow="ellipsis")
    state = BUS_STATES.get(health.get("bus_state", 0.0))
    if state is not None:
        faults.append(state + "  ", "bold red")
    flood = health.get("flood_id", -1.0)
    if flood >= 0:
        faults.append(f"flood 0x{int(flood):03X}  ", "bold red")
    errors = sum(health.get(k, 0.0) for k in ERROR_KEYS)
    for label, value in (("errors", errors), ("lost", health.get("lost", 0.0)),
                         ("late", health.get("late", 0.0)),
                         ("retries", health.get("retries", 0.0))):
        _figure(faults, label, value, bad=value > 0)
    if health.get("duplicates", 0.0) > 0:
        _figure(faults, "dup", health["duplicates"])
    return rates, faults


class LinkPanel(Static):
    """The link's health, or the simulation's clock and speed."""

    DEFAULT_CSS = "LinkPanel { height: auto; }"

    def __init__(self, *, id: str | None = None) -> None:  # noqa: A002
        super().__init__(id=id)
        self._last: object = None
        self.border_title = titled("link", None)
        self.lines_shown = 1
        """How many lines the panel shows (console/roomy.py sizes the column by it)."""

    def show(self, in_process: bool, time_s: float | None, speed: str,
             health: Mapping[str, float], age_s: float | None = None,
             replay: bool = False) -> None:
        """``in_process``: the simulation runs in the console (no link to show);
        ``age_s``: wall seconds since the robot was last read (None: never);
        ``replay``: a recording played back, ``speed`` the replay's."""
        key = (in_process, None if time_s is None else round(time_s, 1), speed,
               tuple(sorted(health.items())), age_key(age_s), replay)
        if key == self._last:
            return
        self._last = key
        stale = is_stale(age_s)
        self.set_class(stale, "-stale")
        if in_process:
            self.border_title = titled("recorded simulation" if replay else "simulation",
                                       age_s)
            out = Text("t ", "dim", no_wrap=True, overflow="ellipsis")
            out.append("—" if time_s is None else f"{time_s:7.1f} s")
            out.append("  replay " if replay else "  speed ", "dim")
            out.append(SPEED_NAMES.get(speed, speed), "bold")
            self.update(without_status(out) if stale else out)
            self.lines_shown = 1
        else:
            self.border_title = titled("recorded link health" if replay else "link health",
                                       age_s)
            lines = health_text(health)
            self.update(Group(*(without_status(line) for line in lines) if stale else lines))
            self.lines_shown = len(lines)
