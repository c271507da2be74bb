"""The six motors: direction, speed (turns/s) and turn counter, and any fault."""

from __future__ import annotations

from collections.abc import Mapping

from rich.text import Text
from textual.widgets import Static

from stairbot.hardware import LIFT_MOTORS, MotorId, MotorState, Snapshot

STILL = 1e-3  # turns/s below which a motor counts as stopped


def direction(motor: MotorId, speed: float) -> tuple[str, str]:
    """A glyph and a style: wheels ▶ forward ◀ back, lifts ▲ up ▼ down, ■ stopped."""
    if abs(speed) < STILL:
        return "■", "dim"
    if motor in LIFT_MOTORS:
        return ("▲", "bold cyan") if speed > 0 else ("▼", "bold cyan")
    return ("▶", "bold green") if speed > 0 else ("◀", "bold yellow")


def motor_line(motor: MotorId, state: MotorState | None, commanded: float | None) -> Text:
    line = Text(f"{motor.value} ", style="bold")
    if state is None:
        line.append("—", "dim")
        return line
    glyph, style = direction(motor, state.speed_tps)
    line.append(glyph, style)
    line.append(f" {state.speed_tps:+6.2f} t/s {state.turns:9.2f} t")
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
        self.border_title = "motors  dir  speed  turns"

    def show(self, snap: Snapshot | None, commands: Mapping[MotorId, float]) -> None:
        motors = dict(snap.motors) if snap is not None else {}
        key = (motors, dict(commands))
        if key == self._last:
            return
        self._last = key
        self.update(Text("\n").join(
            motor_line(m, motors.get(m), commands.get(m) if commands else None)
            for m in MotorId
        ))
