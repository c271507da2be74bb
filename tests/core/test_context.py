"""The context round-trips through JSON, and a restored controller carries on
exactly as one that was never stopped."""

from __future__ import annotations

import json

import pytest
from kinematic import KinematicRobot, run

from stairbot.control.algorithm.context import (
    TAB_SIZE,
    Context,
    Landing,
    Pause,
    StartPosition,
    Watch,
)
from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.families import Calibration, LandingTurn
from stairbot.control.algorithm.limp import Limp
from stairbot.control.algorithm.modes import AscentEnd, CalibrationCase, Purpose
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.work import EdgeWork, LiftWork, ProbeWork, SightWork, StandingWork
from stairbot.control.robot_config import load_config
from stairbot.errors import InputError
from stairbot.hardware import SensorId

CFG = load_config("ideal")  # the algorithm's logic, on the readings it was written for


def test_a_new_context_holds_the_seeds_variables() -> None:
    ctx = Controller(CFG).context
    assert ctx.number_of_steps == 0
    assert ctx.length_of_next_step is None
    assert ctx.number_of_vertical_turns == pytest.approx(CFG.initial_number_of_vertical_turns)
    assert ctx.number_of_turns_for_step_height == 0.0
    assert ctx.tab_length_to_edge == [None] * TAB_SIZE == [None] * 20


def test_round_trip_through_json() -> None:
    ctx = Context(length_of_next_step=0.29, number_of_steps=3, phase="ascent_lift_third",
                  ascent_end=AscentEnd.TOP_REACHED, work=LiftWork(target_mtf=12.5, checked=True),
                  pauses=2)
    ctx.tab_length_to_edge[0] = 0.14
    data = json.loads(json.dumps(ctx.to_dict()))
    assert Context.from_dict(data) == ctx


def test_from_dict_names_a_bad_key_or_value() -> None:
    with pytest.raises(InputError, match="saved.json: colour: unknown key"):
        Context.from_dict({"colour": "red"}, "saved.json")
    with pytest.raises(InputError, match="number_of_steps"):
        Context.from_dict({"number_of_steps": "three"})
    with pytest.raises(InputError, match="number_of_steps"):
        Context.from_dict({"number_of_steps": True})
    with pytest.raises(InputError, match="tab_length_to_edge: must be a list of 20"):
        Context.from_dict({"tab_length_to_edge": [0.1]})
    with pytest.raises(InputError, match="work.colour: unknown key"):
        Context.from_dict({"work": {"kind": "Work", "colour": "red"}})
    with pytest.raises(InputError, match="work.target_mtf"):
        Context.from_dict({"work": {"kind": "LiftWork", "target_mtf": "high"}})
    with pytest.raises(InputError, match="work.target_mtf: unknown key"):
        Context.from_dict({"work": {"kind": "DriveWork", "target_mtf": 1.0}})
    with pytest.raises(InputError, match="work.kind: 'Hammer' is not a kind of Work"):
        Context.from_dict({"work": {"kind": "Hammer"}})
    with pytest.raises(InputError, match="family.kind: None is not a kind of Family"):
        Context.from_dict({"family": {"purpose": "start"}})
    with pytest.raises(InputError, match="family.purpose: 'sideways' is not a Purpose"):
        Context.from_dict({"family": {"kind": "Calibration", "purpose": "sideways"}})
    with pytest.raises(InputError, match="ascent_end: 'bored' is not a AscentEnd"):
        Context.from_dict({"ascent_end": "bored"})


def test_a_restored_controller_continues_like_the_original() -> None:
    robot_a = KinematicRobot(CFG, steps=[(0.17, 0.28)] * 2)
    robot_b = KinematicRobot(CFG, steps=[(0.17, 0.28)] * 2)
    ctrl_a = Controller(CFG)
    ctrl_b = Controller(CFG)
    stop_at = Phase.ASCENT_DRIVE_SECOND  # mid-step, with targets stored
    run(ctrl_a, robot_a, until=lambda c: c.phase is stop_at)
    run(ctrl_b, robot_b, until=lambda c: c.phase is stop_at)
    for _ in range(10):  # part way into the drive
        for ctrl, robot in ((ctrl_a, robot_a), (ctrl_b, robot_b)):
            robot.command(ctrl.tick(robot.read()))
            robot.advance(CFG.algorithm.tick)
    saved = json.dumps(ctrl_b.context.to_dict())
    restored = Controller(CFG, context=Context.from_dict(json.loads(saved)))
    assert restored.phase is stop_at
    sent_a = run(ctrl_a, robot_a)
    sent_b = run(restored, robot_b)
    assert sent_a == sent_b
    assert ctrl_a.result == restored.result
    assert restored.result.outcome == "completed"


def test_the_phases_lists_of_pairs_come_back_as_pairs() -> None:
    """JSON makes a list of a tuple: from_dict restores the declared type
    (the calibration check's ``standing``, the probe's ``probe_recent``)."""
    ctx = Context(work=ProbeWork(standing=[(0.3, 0.31)],
                                 probe_recent=[(0.5, 0.52), (0.5, 0.53)]))
    back = Context.from_dict(json.loads(json.dumps(ctx.to_dict())))
    assert back == ctx
    work = back.work_of(ProbeWork)
    assert work.standing == [(0.3, 0.31)] and isinstance(work.standing[0], tuple)


def test_every_field_round_trips_through_json() -> None:
    """Each field set to a value unlike its default comes back equal, of its type."""
    ctx = Context(
        length_of_next_step=0.3, number_of_vertical_turns=1.5, number_of_steps=2,
        phase="paused", third_in_air=True, steps_descended=1,
        start=StartPosition(reading=0.2, home_twist=0.1),
        landing=Landing(step=2, side=-1), watch=Watch(3, 0.01),
        pause=Pause("cal_probe", 4.0, [0.01, 0.02]),
        limp=Limp(["SFR"], 46.1, "ascent 7 — lift segment 3 (step 1)"),
        family=Calibration(Purpose.DESCENT, case=CalibrationCase.THREE_B, squaring_turns=1),
        work=ProbeWork(entry_wheel=3.0, probe_recent=[(0.1, 0.2)], standing=[(0.3, 0.3)]))
    ctx.tab_length_to_edge[1] = 0.14
    ctx.climb_twist[0] = -0.02
    back = Context.from_dict(json.loads(json.dumps(ctx.to_dict())))
    assert back == ctx
    assert type(back.work.entry_wheel) is float and type(back.number_of_steps) is int
    for other in (LandingTurn(rise_m=[0.17, None], open=[1, -1]),):
        ctx.family = other
        assert Context.from_dict(json.loads(json.dumps(ctx.to_dict()))) == ctx
    for work in (SightWork(sights=[[0.2], [0.3, 0.4]]), EdgeWork(edge_first=SensorId.SBR)):
        ctx.work = work
        assert Context.from_dict(json.loads(json.dumps(ctx.to_dict()))) == ctx


@pytest.mark.parametrize(("data", "problem"), [
    ({"number_of_steps": 10**9}, "number_of_steps: 1000000000 is out of range; allowed: 0 to 20"),
    ({"number_of_steps": 1e9}, "number_of_steps: 1000000000.0 is not of type int"),
    ({"phase_started_s": float("nan")}, "phase_started_s: nan is out of range"),
    ({"work": {"kind": "LiftWork", "target_mtf": float("inf")}},
     "work.target_mtf: inf is out of range"),
    ({"phase": "ascent_fly"}, "phase: 'ascent_fly' is not a phase"),
    ({"pause": {"resume_phase": "ascent_fly", "started_s": 1.0}},
     "pause.resume_phase: 'ascent_fly' is not a phase"),
    ({"work": {"kind": "StandingWork", "standing": [[0.3]]}},
     "work.standing[0]: [0.3] is not of type tuple"),
    ({"landing": {"step": -1}}, "landing.step: -1 is out of range"),
])
def test_from_dict_refuses_numbers_out_of_bounds_and_unknown_phases(
        data: dict[str, object], problem: str) -> None:
    with pytest.raises(InputError) as err:
        Context.from_dict(data, "j")
    assert str(err.value).startswith(f"j: {problem}")


def test_steps_descended_are_bounded_by_those_climbed_unless_from_the_top() -> None:
    with pytest.raises(InputError, match="steps_descended: 3 is out of range; allowed: 0 to 2"):
        Context.from_dict({"number_of_steps": 2, "steps_descended": 3})
    assert Context.from_dict({"from_top": True, "steps_descended": 35}).steps_descended == 35


def test_a_restored_work_of_another_phase_is_refused() -> None:
    ctx = Context(phase="cal_check", phase_started_s=1.0, family=Calibration(),
                  work=StandingWork())
    Controller(CFG, context=ctx)
    ctx.work = LiftWork()
    with pytest.raises(InputError, match="work.kind: LiftWork is not the work of cal_check"):
        Controller(CFG, context=ctx)
    ctx.work, ctx.family = StandingWork(), None
    with pytest.raises(InputError, match="family.kind"):
        Controller(CFG, context=ctx)
