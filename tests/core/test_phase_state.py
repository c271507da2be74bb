"""A phase's state lives as long as the phase: on every tick of whole runs the
context holds the present phase's work (of the class its record names) and
its family's state (none when it has none), and the standing rule's wait
only while it waits.  The context itself holds the seed's variables and the
run's progress, nothing else."""

from __future__ import annotations

from dataclasses import fields
from typing import Any

import pytest
import simrun

from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.phases import Phase
from stairbot.control.robot_config import load_config
from stairbot.hardware import MotorId, Snapshot
from stairbot.inputs.scenario import load_scenario

SEED = ("length_of_next_step", "number_of_vertical_turns", "number_of_turns_for_step_height",
        "number_of_steps", "tab_length_to_edge")
PROGRESS = ("phase", "phase_started_s", "from_top", "steps_descended", "pauses", "ascent_end",
            "outcome", "error", "end_reason", "tread_length", "climb_twist", "second_by_turns",
            "third_in_air",
            "riser_wheel", "start", "descent", "landing", "limp", "watch", "pause")
PRESENT = ("family", "work")


def test_the_context_holds_the_seeds_variables_the_progress_and_the_present_phase() -> None:
    assert tuple(f.name for f in fields(Context)) == SEED + PROGRESS + PRESENT


def _check(ctx: Context) -> None:
    phase = Phase(ctx.phase)
    if phase.terminal:
        return
    if phase is Phase.PAUSED:
        assert ctx.pause is not None
        phase = Phase(ctx.pause.resume_phase)
    else:
        assert ctx.pause is None, phase
    record = phase.record
    assert type(ctx.work) is record.work, (phase, ctx.work)
    if record.family is None:
        assert ctx.family is None, (phase, ctx.family)
    else:
        assert type(ctx.family) is record.family, (phase, ctx.family)


@pytest.mark.parametrize(("config", "scenario"), [
    ("reference", "default"), ("landings", "landing_left"), ("reference", "top_descent"),
    ("reference", "passing_disagreement"), ("heavy_middle", "narrow_steps"),
    ("reference", "step_too_high"), ("landings", "landing_wall"),
])
def test_no_phase_state_outlives_its_phase(config: str, scenario: str,
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    seen: set[Phase] = set()
    original = Controller.tick

    def tick(self: Controller, snap: Snapshot) -> dict[MotorId, float]:
        speeds = original(self, snap)
        _check(self.context)
        seen.add(self.phase)
        return speeds

    monkeypatch.setattr(Controller, "tick", tick)
    result = simrun.run_sim(load_config(config), load_scenario(scenario))
    assert result.outcome in ("completed", "stopped"), result
    assert len(seen) > 5


def test_four_families_of_phases_share_state() -> None:
    families: set[Any] = {p.record.family for p in Phase} - {None}
    assert {f.__name__ for f in families} == {"Calibration", "LiftFirst", "LowerThird",
                                              "LandingTurn"}
