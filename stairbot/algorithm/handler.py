"""What a phase handler sees each tick (:class:`PhaseIO`), what a handler is
(:class:`Handler`), and the handler shapes several phases share: a drive that
ends at a reading (with the seed's turn-count fallback), a lift to absolute
counter targets.

A handler's ``enter`` runs once when its phase is entered afresh (not when the
standing rule resumes it); it stores absolute targets in the context.  Its
``step`` runs every tick after that and returns the motor speeds; it ends the
phase by calling :meth:`PhaseIO.go` (or ``fail`` / ``end``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from stairbot.algorithm import motion
from stairbot.algorithm.context import Context
from stairbot.algorithm.phases import BY_VALUE, Mode, Phase
from stairbot.algorithm.transitions import TRANSITIONS
from stairbot.config import RobotConfig
from stairbot.events import EventKind
from stairbot.hardware import MotorId, Snapshot

Speeds = dict[MotorId, float]


class Machine(Protocol):
    """The controller, as the handlers reach it."""

    def transition(self, phase: Phase, why: str, snap: Snapshot) -> None: ...

    def fail(self, reason: str, snap: Snapshot) -> None: ...

    def end(self, outcome: str, reason: str, snap: Snapshot) -> None: ...

    def pause(self, reason: str, snap: Snapshot) -> None: ...

    def resume(self, reason: str, snap: Snapshot) -> None: ...

    def emit(self, kind: EventKind, message: str, snap: Snapshot,
             data: dict[str, Any] | None = None) -> None: ...


@dataclass
class PhaseIO:
    """One tick's view for a handler: the snapshot, the config, the context."""

    snap: Snapshot
    cfg: RobotConfig
    ctx: Context
    mode: Mode
    machine: Machine

    @property
    def phase(self) -> Phase:
        return BY_VALUE[self.ctx.phase]

    def go(self, phase: Phase) -> None:
        """Enter ``phase``; the table's condition is the reason given."""
        self.machine.transition(phase, TRANSITIONS.get(self.phase, {}).get(phase, ""), self.snap)

    def fail(self, reason: str) -> None:
        """End the program with an error."""
        self.machine.fail(reason, self.snap)

    def end(self, outcome: str, reason: str) -> None:
        """End the program with ``outcome`` ("completed" or "stopped")."""
        self.machine.end(outcome, reason, self.snap)

    def info(self, message: str, **data: Any) -> None:
        """Tell a measurement or a decision (an INFO event)."""
        self.machine.emit(EventKind.INFO, message, self.snap, data)

    @property
    def descent_index(self) -> int:
        """0-based index of the step being descended (into tab_length_to_edge)."""
        return self.ctx.number_of_steps - self.ctx.steps_descended - 1


def where(ctx: Context, phase: Phase) -> str:
    """Where in the program ``phase`` stands, for messages: "start", "ascent 1,
    step 3", "step 2"; empty outside the steps."""
    if phase.flow == "calibration":
        if ctx.purpose == "start":
            return "start"
        if ctx.purpose == "ascent":
            return f"ascent 1, step {ctx.number_of_steps + 1}"
        return f"descent 1, step {ctx.number_of_steps - ctx.steps_descended}"
    if phase.flow == "ascent":
        counted = phase in (Phase.ASCENT_CHECK, Phase.ASCENT_DRIVE_THIRD)
        return f"step {ctx.number_of_steps + (0 if counted else 1)}"
    if phase.flow == "descent" and phase is not Phase.DESCENT_FINISH:
        return f"step {ctx.number_of_steps - ctx.steps_descended}"
    return ""


def _nothing(_io: PhaseIO) -> None:
    return None


@dataclass(frozen=True)
class Handler:
    step: Callable[[PhaseIO], Speeds]
    enter: Callable[[PhaseIO], None] = _nothing


def reading_drive(
    direction: int,
    target: Callable[[PhaseIO], float | None],
    fallback_turns: Callable[[PhaseIO], float],
    done: Callable[[PhaseIO], None],
) -> Handler:
    """A drive (``direction`` +1 forward, -1 back) that ends when the mean
    SFR/SFL reading reaches ``target(io)`` metres.

    While the front sensors are measurable the target is re-expressed as an
    absolute wheel-counter target every tick (dead reckoning from the latest
    reading); while they are not, the drive carries on to the last such
    target — or, if they never were, to ``fallback_turns(io)`` turns from the
    phase's start (the seed's "not measurable" fallback).  A ``target`` of
    None means a drive by turns only.  ``done(io)`` chooses the next phase.
    """

    def enter(io: PhaseIO) -> None:
        io.ctx.target_reading = target(io)
        io.ctx.target_wheel = io.ctx.entry_wheel + direction * fallback_turns(io)

    def step(io: PhaseIO) -> Speeds:
        ctx, cfg = io.ctx, io.cfg
        here = motion.wheel_position(io.snap)
        if ctx.target_reading is not None and motion.measurable(io.snap, cfg):
            remaining_m = direction * (motion.mean_distance(io.snap) - ctx.target_reading)
            ctx.target_wheel = here + direction * cfg.wheel_turns(remaining_m)
        assert ctx.target_wheel is not None  # set on entry
        remaining = direction * (ctx.target_wheel - here)
        if remaining <= motion.WHEEL_DONE:
            done(io)
            return {}
        return motion.drive(cfg, direction, remaining)

    return Handler(step, enter)


def turns_drive(direction: int, turns: Callable[[PhaseIO], float],
                done: Callable[[PhaseIO], None]) -> Handler:
    """A drive of ``turns(io)`` wheel turns (``direction`` +1 forward, -1 back)."""
    return reading_drive(direction, lambda _io: None, turns, done)


def lift(targets: Callable[[PhaseIO], dict[MotorId, float]],
         done: Callable[[PhaseIO], None]) -> Handler:
    """Lifts to absolute counters, all at once: ``targets(io)`` on entry gives
    them relative to the entry counters, as {MTF: delta, MTB: delta}."""

    def enter(io: PhaseIO) -> None:
        deltas = targets(io)
        io.ctx.target_mtf = io.ctx.entry_mtf + deltas[MotorId.MTF] if MotorId.MTF in deltas \
            else None
        io.ctx.target_mtb = io.ctx.entry_mtb + deltas[MotorId.MTB] if MotorId.MTB in deltas \
            else None

    def step(io: PhaseIO) -> Speeds:
        speeds = motion.lifts_to(io.cfg, io.snap, lift_targets(io.ctx))
        if speeds is None:
            done(io)
            return {}
        return speeds

    return Handler(step, enter)


def lift_targets(ctx: Context) -> dict[MotorId, float]:
    """The context's lift targets that are set."""
    out: dict[MotorId, float] = {}
    if ctx.target_mtf is not None:
        out[MotorId.MTF] = ctx.target_mtf
    if ctx.target_mtb is not None:
        out[MotorId.MTB] = ctx.target_mtb
    return out
