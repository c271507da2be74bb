"""The phase list and the transition table: complete, consistent, enforced."""

from __future__ import annotations

import ast
import math
import re
from dataclasses import replace
from pathlib import Path

import pytest

from stairbot.control.algorithm import phases
from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.families import Calibration
from stairbot.control.algorithm.modes import CalibrationCase
from stairbot.control.algorithm.phase import ENDED, FAILED, Step, Tick, go
from stairbot.control.algorithm.phases import FLOWS, Mode, Phase
from stairbot.control.algorithm.squaring import STILL_TICKS
from stairbot.control.algorithm.standing import DISAGREE, resumed
from stairbot.control.algorithm.transitions import (
    BACK_PAIR_PHASES,
    EXITS,
    STANDING_ARMED,
    TRANSITIONS,
    allowed,
    mermaid,
)
from stairbot.control.algorithm.work import StandingWork
from stairbot.control.robot_config import load_config
from stairbot.control.tolerances import settle_s
from stairbot.errors import TransitionError
from stairbot.hardware import Imu, MotorId, MotorState, SensorId, SensorReading, Snapshot

CFG = load_config("ideal")  # the algorithm's logic, on the readings it was written for


def snapshot(t: float = 0.0, front: float = 0.5) -> Snapshot:
    sensors = {SensorId.SFR: SensorReading(front), SensorId.SFL: SensorReading(front),
               SensorId.SBR: SensorReading(0.04), SensorId.SBL: SensorReading(0.04)}
    return Snapshot(t, sensors, {m: MotorState(0.0) for m in MotorId}, imu=Imu(0.0, 0.0))


def test_every_phase_has_a_seed_label_and_a_flow() -> None:
    for phase in Phase:
        assert phase.flow in (*FLOWS, "end", "landing")  # landing: an extension's own
        assert phase.label and "—" in phase.label
        if phase.flow in ("ascent", "descent"):
            assert re.match(rf"{phase.flow} \d — ", phase.label), phase.label
    assert Phase.ASCENT_LIFT_FIRST.label == "ascent 3 — lift segment 1"


def test_seed_steps_each_have_a_phase() -> None:
    labels = [p.label for p in Phase]
    for n in range(2, 10):
        assert any(label.startswith(f"ascent {n} — ") for label in labels), n
    for n in range(1, 8):
        assert any(label.startswith(f"descent {n} — ") for label in labels), n
    for case in ("case 2", "case 3", "case 3B"):
        assert any(case in label for label in labels), case


def test_the_table_covers_every_phase_and_every_active_phase_has_a_step() -> None:
    assert set(TRANSITIONS) == set(Phase)
    for phase in Phase:
        assert phase.record.phase is phase
        if phase.terminal:
            assert TRANSITIONS[phase] == {}
            assert phase.record.step is None
        else:
            assert phase.record.step is not None, phase
            assert Phase.ERROR in TRANSITIONS[phase], phase  # faults end anywhere
            assert EXITS[phase][FAILED].phase is Phase.ERROR, phase


def test_every_outcome_of_every_record_leads_to_a_phase_the_table_allows() -> None:
    """Each record's outcomes, and the pauses and resumes the table adds, lead
    where the transition table (and so the flowcharts) says; ERROR only on
    a failure, DONE only on an end, and a failure always to ERROR."""
    for phase in Phase:
        for happened, ex in phase.record.on.items():
            assert allowed(phase, ex.phase), (phase, happened)
            assert ex.when in TRANSITIONS[phase][ex.phase], (phase, happened)
            assert (ex.phase is Phase.ERROR) is (happened == FAILED), (phase, happened)
            assert (ex.phase is Phase.DONE) is (happened == ENDED), (phase, happened)
            assert EXITS[phase][happened].phase is ex.phase
        for happened, ex in EXITS[phase].items():
            assert allowed(phase, ex.phase), (phase, happened)
            assert happened in phase.record.on or happened == DISAGREE or (
                phase is Phase.PAUSED and happened == resumed(ex.phase)), (phase, happened)
        # every transition of the table comes from an outcome
        assert set(TRANSITIONS[phase]) == {ex.phase for ex in EXITS[phase].values()}


def test_every_outcome_a_step_names_is_listed_by_a_record() -> None:
    """An outcome spelled in a step (``go("...")``, ``calibrate("...", ...)``)
    that no record lists would raise TransitionError only when that branch
    runs: every such literal in the algorithm's modules is some record's."""
    listed = {happened for phase in Phase for happened in phase.record.on}
    package = Path(phases.__file__).parent
    named = set()
    for module in package.glob("*.py"):
        for node in ast.walk(ast.parse(module.read_text("utf-8"))):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                    and node.func.id in ("go", "calibrate") and node.args \
                    and isinstance(node.args[0], ast.Constant):
                named.add((module.name, node.args[0].value))
    assert len(named) > 40
    assert {(m, h) for m, h in named if h not in listed} == set()


def test_a_step_returns_what_happened_and_enters_nothing_itself() -> None:
    """A phase's step is a function of (context, readings): it says what
    happened; the table says where that leads, and only the controller
    enters it."""
    ctx = Context(phase=Phase.CAL_CHECK.value, family=Calibration())
    said: list[str] = []
    sensors = {SensorId.SFR: SensorReading(0.50), SensorId.SFL: SensorReading(0.53),
               SensorId.SBR: SensorReading(0.04), SensorId.SBL: SensorReading(0.04)}
    motors = {m: MotorState(0.0) for m in MotorId}
    record = Phase.CAL_CHECK.record
    assert record.step is not None
    work = StandingWork.at_entry(Snapshot(0.0, sensors, motors))
    # the filter settles, then the pair is averaged over STILL_TICKS, standing still
    ticks = math.ceil(settle_s(CFG) / CFG.algorithm.tick - 1e-9) + STILL_TICKS + 1
    steps = []
    for i in range(ticks):
        snap = Snapshot(i * CFG.algorithm.tick, sensors, motors)
        tick = Tick(snap, CFG, ctx, Mode.FULL, lambda message, **_: said.append(message))
        steps.append(record.step(tick, work))
    assert all(isinstance(s, Step) and not s.speeds for s in steps)
    assert [s.happened for s in steps[:-1]] == [None] * (ticks - 1)
    step = steps[-1]
    assert step.happened == "case_found"
    assert EXITS[Phase.CAL_CHECK]["case_found"].phase is Phase.CAL_LIFT
    assert ctx.phase == Phase.CAL_CHECK.value  # not entered by the step
    # the calibration's state and a message
    assert ctx.family_of(Calibration).case is CalibrationCase.TWO and said
    assert Phase.CAL_LIFT in TRANSITIONS[Phase.CAL_CHECK]


def test_every_phase_is_reachable_from_the_start() -> None:
    seen, todo = {Phase.CAL_CHECK}, [Phase.CAL_CHECK]
    while todo:
        for nxt in TRANSITIONS[todo.pop()]:
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    assert seen == set(Phase)


def test_standing_rule_is_armed_where_the_table_says_and_not_while_turning_or_rising() -> None:
    assert Phase.CAL_TURN not in STANDING_ARMED
    assert Phase.CAL_PROBE not in STANDING_ARMED
    assert Phase.ASCENT_LIFT_FIRST not in STANDING_ARMED
    assert Phase.ASCENT_LIFT_FIRST_MORE not in STANDING_ARMED
    assert Phase.ASCENT_APPROACH in STANDING_ARMED
    assert BACK_PAIR_PHASES == {Phase.DESCENT_LOWER_THIRD}
    for phase in STANDING_ARMED:
        assert allowed(Phase.PAUSED, phase)


@pytest.mark.parametrize("bad", [go("no_step_climbed"), go("squared"), Step(happened=ENDED)])
def test_a_step_that_returns_an_outcome_its_phase_does_not_list_raises(
        monkeypatch: pytest.MonkeyPatch, bad: Step) -> None:
    ctrl = Controller(CFG)
    n = 0
    while ctrl.phase is not Phase.CAL_LIFT:  # enters calibration, case 3: lift
        ctrl.tick(snapshot(n * CFG.algorithm.tick))
        n += 1
        assert n < 100
    rogue = replace(Phase.CAL_LIFT.record, step=lambda _t, _w: bad)
    monkeypatch.setitem(phases._records(), Phase.CAL_LIFT, rogue)
    with pytest.raises(TransitionError, match=f"{bad.happened!r} is not an outcome of cal_lift"):
        ctrl.tick(snapshot(n * CFG.algorithm.tick))
    assert ctrl.phase is Phase.CAL_LIFT


def test_mermaid_draws_every_edge_of_its_flow() -> None:
    for flow in FLOWS:
        chart = mermaid(flow)
        for src, nexts in TRANSITIONS.items():
            if src.flow != flow:
                continue
            for dst, label in nexts.items():
                assert f'{src.value} -->|"{label}"| {dst.value}' in chart
    with pytest.raises(ValueError, match="unknown flow"):
        mermaid("sideways")
