"""What a phase is (:class:`PhaseDef`), what its step sees (:class:`Tick`) and
returns (:class:`Step`).

A phase is one record: its seed name, its flow, its entry action, its step and
its transitions (the next phases it may return, each with the condition that
makes it).  The transition table and the flowcharts are drawn from these
records (:mod:`stairbot.control.algorithm.transitions`).

A step is a function of (the tick's readings and context, the phase's work)
that returns a :class:`Step`: the motor speeds to command and, when the phase
is over, which phase comes next.  Only the controller enters a phase, once per
tick at most, in one place.  A step may update the seed's variables and
the run's progress in the context (``number_of_steps``,
``tab_length_to_edge``...), its family's state and its own work; nothing
else.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Generic, TypeVar

from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.families import Calibration, Family
from stairbot.control.algorithm.modes import LANDING_PURPOSES, Outcome, Purpose
from stairbot.control.algorithm.phases import Mode, Phase
from stairbot.control.algorithm.work import Work
from stairbot.hardware import Snapshot, Speeds
from stairbot.inputs.config import RobotConfig

FAULT = "sensor error, motor fault or phase timeout"
FRONT_DISAGREE = "SFR ≠ SFL for 3 ticks"
BACK_DISAGREE = "SBR ≠ SBL for 3 ticks"

W = TypeVar("W", bound=Work)

NO_MOTION: Speeds = MappingProxyType({})
"""A step that commands nothing: every motor stops (lifts hold)."""


@dataclass(frozen=True, slots=True)
class Step:
    """What one tick of a phase decides.

    ``next`` is None while the phase goes on.  Entering ERROR or DONE ends the
    program: ``reason`` says why, and ``outcome`` (COMPLETED or STOPPED)
    what DONE means.  For any other phase ``reason`` overrides the table's
    condition in the event that tells the transition.  ``begin``: the state
    the next phase's family begins with (see
    :mod:`~stairbot.control.algorithm.families`)."""

    speeds: Speeds = field(default_factory=lambda: NO_MOTION)
    next: Phase | None = None
    reason: str | None = None
    outcome: Outcome | None = None
    begin: Family | None = None


def stay(speeds: Speeds) -> Step:
    """Carry on in this phase, commanding ``speeds``."""
    return Step(speeds)


def go(phase: Phase, reason: str | None = None, begin: Family | None = None) -> Step:
    """End this phase (every motor stops for this tick) and enter ``phase``
    (its family beginning with ``begin``, if given)."""
    return Step(NO_MOTION, phase, reason, begin=begin)


def calibrate(purpose: Purpose, turn_to: float | None = None,
              reason: str | None = None) -> Step:
    """Enter calibration for ``purpose``: its check, or, to turn to the
    heading ``turn_to``, its lift."""
    phase = Phase.CAL_CHECK if turn_to is None else Phase.CAL_LIFT
    return go(phase, reason, Calibration(purpose, turn_to))


def fail(reason: str) -> Step:
    """End the program with an error."""
    return Step(NO_MOTION, Phase.ERROR, reason)


def end(outcome: Outcome, reason: str) -> Step:
    """End the program with ``outcome`` (COMPLETED or STOPPED)."""
    return Step(NO_MOTION, Phase.DONE, reason, outcome)


Say = Callable[..., None]


@dataclass(frozen=True, slots=True)
class Tick:
    """One tick as a phase sees it: the readings, the config, the context, the
    mode, and ``say`` to tell a measurement or a decision (an INFO event)."""

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
    saying so in ``to``.  ``carried_by`` names the segments (1, 2, 3) whose
    wheels carry the robot while the phase moves its lifts: the
    static-stability check runs before its first step
    (:mod:`stairbot.control.algorithm.stability`), and its error is added to
    the edge to ERROR, also without saying so in ``to``; empty: no lift moves."""

    phase: Phase
    label: str
    flow: str
    step: Callable[[Tick, W], Step] | None
    work: type[W]
    to: Mapping[Phase, str] = field(default_factory=dict)
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

