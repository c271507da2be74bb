"""What a phase is (:class:`PhaseDef`), what its step sees (:class:`Tick`) and
returns (:class:`Step`).

A phase is one record: its seed name, its flow, its entry action, its step and
its outcomes (what its step may say happened, each with the :class:`Exit` it
leads to: the next phase and the condition, in words).  The transition table
and the flowcharts are drawn from these records
(:mod:`stairbot.control.algorithm.transitions`).

A step is a function of (the tick's readings and context, the phase's work)
that returns a :class:`Step`: the motor speeds to command and, when the phase
is over, what happened (an outcome its record lists).  The step never names
the next phase: the controller looks the outcome up in the table and enters
the phase it leads to, once per tick at most, in one place.  A step may
update the seed's variables and the run's progress in the context
(``number_of_steps``, ``tab_length_to_edge``...), its family's state and its
own work; nothing else.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Generic, NamedTuple, TypeVar

from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.families import Calibration, Family
from stairbot.control.algorithm.modes import LANDING_PURPOSES, Outcome, Purpose
from stairbot.control.algorithm.phases import Mode, Phase
from stairbot.control.algorithm.work import Work
from stairbot.hardware import SensorId, Snapshot, Speeds
from stairbot.inputs.config import RobotConfig

FAULT = "sensor error, motor fault or phase timeout"
FRONT_DISAGREE = "SFR ≠ SFL for 3 ticks"
BACK_DISAGREE = "SBR ≠ SBL for 3 ticks"

W = TypeVar("W", bound=Work)

NO_MOTION: Speeds = MappingProxyType({})
"""A step that commands nothing: every motor stops (lifts hold)."""


FAILED = "failed"
"""The outcome of :func:`fail`: every record lists it (faults end anywhere)."""
ENDED = "ended"
"""The outcome of :func:`end`, in the records of the phases that may end the
program."""


@dataclass(frozen=True, slots=True)
class Exit:
    """Where an outcome of a phase leads: the next phase, and ``when``, the
    condition in words (the flowcharts' edge label, the transition's "why")."""

    phase: Phase
    when: str


class Step(NamedTuple):
    """What one tick of a phase decides (a named tuple: immutable, and quick
    to make, as one is every tick).

    ``happened`` is None while the phase goes on; else the outcome that ends
    it, which the phase's record maps to the next phase (:class:`Exit`).
    Ending in ERROR or DONE ends the program: ``reason`` says why, and
    ``outcome`` (COMPLETED or STOPPED) what DONE means.  For any other
    phase ``reason`` overrides the exit's condition in the event that tells
    the transition.  ``begin``: the state the next phase's family begins
    with (see :mod:`~stairbot.control.algorithm.families`).  ``wrong``: a
    sensor the phase found reading wrong, and why (:func:`distrust`)."""

    speeds: Speeds = NO_MOTION
    happened: str | None = None
    reason: str | None = None
    outcome: Outcome | None = None
    begin: Family | None = None
    wrong: tuple[SensorId, str] | None = None


def stay(speeds: Speeds) -> Step:
    """Carry on in this phase, commanding ``speeds``."""
    return Step(speeds)


def go(happened: str, reason: str | None = None, begin: Family | None = None) -> Step:
    """End this phase on the outcome ``happened`` (every motor stops for this
    tick); the next phase's family begins with ``begin``, if given."""
    return Step(NO_MOTION, happened, reason, begin=begin)


def calibrate(happened: str, purpose: Purpose, turn_to: float | None = None,
              reason: str | None = None) -> Step:
    """End this phase on ``happened``, whose exit is calibration for
    ``purpose``: its check (CAL_CHECK), or, to turn to the heading
    ``turn_to``, its lift (CAL_LIFT)."""
    return go(happened, reason, Calibration(purpose, turn_to))


def fail(reason: str) -> Step:
    """End the program with an error (the outcome :data:`FAILED`)."""
    return Step(NO_MOTION, FAILED, reason)


def distrust(sensor: SensorId, why: str) -> Step:
    """Stop (this tick) in this phase: ``sensor`` reads wrong, for ``why``.
    If its measurements held one value, perception reads it as ERROR from
    the next tick on while that value holds
    (:meth:`~stairbot.control.perception.Perception.distrust`), as it does a
    stuck one: the sensor hold stands the robot, and it is then lost.  If
    not, the phase goes on, and must not ask again (it ends the run as it
    would have)."""
    return Step(NO_MOTION, wrong=(sensor, why))


def end(outcome: Outcome, reason: str) -> Step:
    """End the program with ``outcome`` (COMPLETED or STOPPED; the phase's
    outcome :data:`ENDED`)."""
    return Step(NO_MOTION, ENDED, reason, outcome)


Say = Callable[..., None]


class Tick(NamedTuple):
    """One tick as a phase sees it: the readings, the config, the context, the
    mode, and ``say`` to tell a measurement or a decision (an INFO event).
    A named tuple, as :class:`Step` is."""

    snap: Snapshot
    cfg: RobotConfig
    ctx: Context
    mode: Mode
    say: Say

    @property
    def descent_index(self) -> int:
        """0-based index of the step being descended (into tab_length_to_edge):
        counted down from the top step climbed, or, in a continuous descent,
        up from the top (the last entry serves every step past it)."""
        ctx = self.ctx
        if ctx.from_top:
            return min(ctx.steps_descended, len(ctx.tab_length_to_edge) - 1)
        return ctx.number_of_steps - ctx.steps_descended - 1

    @property
    def cal(self) -> Calibration:
        """The calibration's state (in a calibration phase)."""
        return self.ctx.family_of(Calibration)


def _no_entry(_t: Tick, _w: Any) -> None:
    return None


@dataclass(frozen=True)
class PhaseDef(Generic[W]):
    """One phase of the algorithm, whole.

    ``work`` is the class of the phase's own work, made afresh on entry;
    ``family`` the class of the state its family shares (None: none), made
    when the program enters the family from another (or handed by the step
    that enters it: ``Step.begin``).  ``watches`` names the sensor pair the
    standing rule watches in this phase ("front" or "back"; None: not armed);
    an armed phase may be paused, and is resumed from the pause, without
    saying so in ``on``.  ``carried_by`` names the segments (1, 2, 3) whose
    wheels carry the robot while the phase moves its lifts: the
    static-stability check runs before its first step
    (:mod:`stairbot.control.algorithm.stability`), and its error is added to
    the condition of :data:`FAILED`, also without saying so in ``on``; empty:
    no lift moves.  ``on``: outcome -> :class:`Exit`, every outcome the step
    may return."""

    phase: Phase
    label: str
    flow: str
    step: Callable[[Tick, W], Step] | None
    work: type[W]
    on: Mapping[str, Exit] = field(default_factory=dict)
    enter: Callable[[Tick, W], None] = _no_entry
    watches: str | None = None
    carried_by: tuple[int, ...] = ()
    family: type[Family] | None = None


def where(ctx: Context, phase: Phase) -> str:
    """Where in the program ``phase`` stands, for messages: "start", "ascent 1,
    step 3", "step 2"; empty outside the steps."""
    flow = phase.flow
    if flow == "calibration":
        purpose = ctx.family_of(Calibration).purpose
        if purpose is Purpose.START:
            return "start"
        if purpose is Purpose.ASCENT:
            return f"ascent 1, step {ctx.number_of_steps + 1}"
        if purpose in (Purpose.HOME, Purpose.FLOOR):
            return "descent 7"
        if purpose in LANDING_PURPOSES:
            return f"the landing after step {ctx.landing.step or ctx.number_of_steps}"
        return f"descent 1, {_step_down(ctx)}"
    if flow == "ascent":
        counted = phase in (Phase.ASCENT_CHECK, Phase.ASCENT_DRIVE_THIRD)
        return f"step {ctx.number_of_steps + (0 if counted else 1)}"
    if flow == "landing":
        return f"the landing after step {ctx.landing.step or ctx.number_of_steps}"
    if flow == "descent" and phase not in (Phase.DESCENT_FINISH, Phase.DESCENT_FINISH_FLOOR):
        return _step_down(ctx)
    return ""


def _step_down(ctx: Context) -> str:
    """The step being descended: "step 3" (as climbed), or in a continuous
    descent "step 2 from the top"."""
    if ctx.from_top:
        return f"step {ctx.steps_descended + 1} from the top"
    return f"step {ctx.number_of_steps - ctx.steps_descended}"

