"""The context round-trips through JSON, and a restored controller carries on
exactly as one that was never stopped."""

from __future__ import annotations

import json

import pytest
from kinematic import KinematicRobot, run

from stairbot.algorithm.context import TAB_SIZE, Context
from stairbot.algorithm.controller import Controller
from stairbot.algorithm.phases import Phase
from stairbot.algorithm.work import Work
from stairbot.config import load_config
from stairbot.errors import InputError

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
                  ascent_end="top_reached", work=Work(target_mtf=12.5, checked=True), pauses=2)
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
        Context.from_dict({"work": {"colour": "red"}})
    with pytest.raises(InputError, match="work.target_mtf"):
        Context.from_dict({"work": {"target_mtf": "high"}})


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
