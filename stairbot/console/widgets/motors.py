"""The six motors: what each moves (operator words first, the seed's name
beside it), its direction, speed (turns/s) and turn counter, and any fault.

A lift's arrow shows the segment that moves, not the motor's sign: with
segments 2 and 3 standing, MTF turning positive raises segment 1 (``1▲``);
with segments 1 and 3 standing, the same sign lowers segment 2 (``2▼``).
Which segments stand is the running phase's ``carried_by``; with no phase
to say (idle), the arrow is the end segment's motion relative to segment 2,
which is what the sign means (docs/protocol.md, section 1).
"""

from __future__ import annotations

from rich.text import Text
from textual.widgets import Static

from stairbot.console.freshness import STILL_TPS, age_key, is_stale, titled, without_status
from stairbot.hardware import LIFT_MOTORS, MotorId, MotorState, Snapshot, Speeds

NAMES = {MotorId.MWF: "front wheels", MotorId.MWB: "back wheels",
         MotorId.MWR: "mid wheels R", MotorId.MWL: "mid wheels L",
         MotorId.MTF: "front lift", MotorId.MTB: "back lift"}
END_SEGMENT = {MotorId.MTF: 1, MotorId.MTB: 3}  # the segment a lift raises against segment 2
SEGMENT_STYLES = ("bold bright_cyan", "bold yellow", "bold magenta")  # as the picture


def lift_motion(motor: MotorId, speed: float, carried_by: tuple[int, ...] = ()) -> tuple[int, str]:
    """(segment, arrow) for a lift turning at ``speed``: the segment that
    moves and which way.  When the end segment stands (it is in
    ``carried_by``), the lift moves segment 2 the other way."""
    end = END_SEGMENT[motor]
    up = speed > 0
    if end in carried_by:
        return 2, "▼" if up else "▲"
    return end, "▲" if up else "▼"


def direction(motor: MotorId, speed: float,
              carried_by: tuple[int, ...] = ()) -> tuple[str, str]:
    """A glyph and a style: wheels ▶ forward ◀ back; lifts the segment and
    ▲ up ▼ down (``1▲``); ■ stopped."""
    if abs(speed) < STILL_TPS:
        return "■", "dim"
    if motor in LIFT_MOTORS:
        segment, arrow = lift_motion(motor, speed, carried_by)
        return f"{segment}{arrow}", SEGMENT_STYLES[segment - 1]
    return ("▶", "bold green") if speed > 0 else ("◀", "bold yellow")


def motor_line(motor: MotorId, state: MotorState | None, commanded: float | None,
               carried_by: tuple[int, ...] = (), stale: bool = False) -> Text:
    """``front lift   MTF 1▲ +10.0    95.0``: name, seed name, direction,
    speed (turns/s), turn counter; then a fault or the commanded speed.
    ``stale``: the values are old (:mod:`~stairbot.console.freshness`): no
    arrow (``?``: how it moves now is not known), no colour, no command."""
    line = Text(f"{NAMES[motor]:<12} ", style="bold")
    line.append(f"{motor.value} ", "dim")
    if state is None:
        line.append("—", "dim")
        return line
    # the arrow and the figure share STILL_TPS: no "-0.0", no arrow beside "+0.0"
    speed = state.speed_tps if abs(state.speed_tps) >= STILL_TPS else 0.0
    figures = f" {speed:+5.1f} {state.turns:7.1f}"
    if stale:
        line.append(f"?{figures}")
        return without_status(line)
    glyph, style = direction(motor, state.speed_tps, carried_by)
    line.append(f"{glyph:<2}", style)
    line.append(figures)
    if state.fault:
        line.append(f" {state.fault}", "bold red")
    elif commanded is not None and abs(commanded - state.speed_tps) > 0.05:
        line.append(f" →{commanded:+.1f}", "dim")
    return line


class MotorPanel(Static):
    """One line per motor, wheels first, then the lifts."""

    DEFAULT_CSS = "MotorPanel { height: auto; }"

    def __init__(self, *, id: str | None = None) -> None:  # noqa: A002
        super().__init__(id=id)
        self._last: object = ()
        self.border_title = titled("motors  turn/s  turns", None)

    def show(self, snap: Snapshot | None, commands: Speeds,
             age_s: float | None = None, carried_by: tuple[int, ...] = ()) -> None:
        """``age_s``: wall seconds since ``snap`` was read (None: never);
        ``carried_by``: the segments that stand in the running phase."""
        motors = dict(snap.motors) if snap is not None else {}
        key = (motors, dict(commands), age_key(age_s), carried_by)
        if key == self._last:
            return
        self._last = key
        self.border_title = titled("motors  turn/s  turns", age_s)
        stale = is_stale(age_s)
        self.set_class(stale, "-stale")
        self.update(Text("\n").join(
            motor_line(m, motors.get(m), commands.get(m) if commands else None, carried_by,
                       stale)
            for m in MotorId
        ))
