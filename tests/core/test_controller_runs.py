"""Whole programs against the kinematic robot: every end of the ascent, the
descent back to the start, the events told on the way."""

from __future__ import annotations

import pytest
from kinematic import KinematicRobot, run

from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.families import Calibration
from stairbot.control.algorithm.modes import CalibrationCase
from stairbot.control.algorithm.phases import Mode, Phase
from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind
from stairbot.hardware import LIFT_MOTORS, MotorId

CFG = load_config("ideal")  # the algorithm's logic, on the readings it was written for
STEP = (0.17, 0.28)


def go(**kw: object) -> tuple[Controller, KinematicRobot, list[Event], list[dict[MotorId, float]]]:
    events: list[Event] = []
    mode = kw.pop("mode", Mode.FULL)
    ctrl = Controller(CFG, events.append, mode)  # type: ignore[arg-type]
    robot = KinematicRobot(CFG, **kw)  # type: ignore[arg-type]
    sent = run(ctrl, robot)
    return ctrl, robot, events, sent


def phases(events: list[Event]) -> list[Phase]:
    return [Phase(e.data["phase"]) for e in events if e.kind is EventKind.PHASE]


def infos(events: list[Event]) -> list[str]:
    return [e.message for e in events if e.kind is EventKind.INFO]


@pytest.fixture(scope="module")
def default_run() -> tuple[Controller, KinematicRobot, list[Event], list[dict[MotorId, float]]]:
    return go()


def test_default_stairs_up_to_the_top_and_back_to_the_start(default_run) -> None:  # type: ignore[no-untyped-def]
    ctrl, robot, events, sent = default_run
    r = ctrl.result
    assert (r.outcome, r.ascent_end, r.steps_climbed, r.steps_descended, r.pauses) == \
        ("completed", "top_reached", 5, 5, 0)
    assert r.error is None
    assert ctrl.finished and ctrl.phase is Phase.DONE
    assert robot.front_x == pytest.approx(robot.start_front_x, abs=0.003)
    assert robot.counters[MotorId.MTF] == pytest.approx(0.0, abs=0.05)
    assert robot.counters[MotorId.MTB] == pytest.approx(0.0, abs=0.05)
    assert events[-1].kind is EventKind.END and events[-1].data["outcome"] == "completed"


def test_default_run_walks_every_phase_but_the_obstacle_and_corner(default_run) -> None:  # type: ignore[no-untyped-def]
    _, _, events, _ = default_run
    seen = set(phases(events))
    # level rays square up from anywhere: no closing in, so nothing to retrace
    not_expected = {Phase.ASCENT_LOWER_OBSTACLE, Phase.CAL_CORNER, Phase.CAL_AWAY,
                    Phase.PAUSED, Phase.ERROR, Phase.CAL_CLOSE_IN, Phase.CAL_TURN_TO,
                    Phase.DESCENT_FINISH_FLOOR, Phase.DESCENT_REFUSE}
    landings = {p for p in Phase if p.flow == "landing"}  # a robot without the side pair
    assert seen == set(Phase) - not_expected - landings


def test_every_phase_change_is_one_phase_event_naming_the_seed_step(default_run) -> None:  # type: ignore[no-untyped-def]
    _, _, events, _ = default_run
    for e in events:
        if e.kind is EventKind.PHASE:
            assert e.message.startswith(Phase(e.data["phase"]).label)
    seq = phases(events)
    assert all(a is not b for a, b in zip(seq, seq[1:], strict=False))
    assert "ascent 3 — lift segment 1 (step 2)" in [e.message for e in events]


def test_measurements_are_told_and_stored(default_run) -> None:  # type: ignore[no-untyped-def]
    ctrl, _, events, _ = default_run
    ctx = ctrl.context
    told = infos(events)
    # riser 0.01 m ahead after the approach: tread + 0.01 m
    assert told.count("length_of_next_step = 0.290 m") == 4
    # the top step sees nothing ahead: its drives and its descent go by turns
    assert any("length_of_next_step not measurable" in m for m in told)
    assert ctx.tab_length_to_edge[:4] == pytest.approx([0.14] * 4, abs=0.002)
    assert ctx.tab_length_to_edge[4] is None
    assert any(m.startswith("tab_length_to_edge[4] not measurable") for m in told)
    heights = [e.data["number_of_turns_for_step_height"] for e in events
               if "number_of_turns_for_step_height" in e.data]
    # ascent: the beam (0.03 m) sees over 0.17 m after 70 turns, + 19 more
    # (the median filter sees it two ticks late: 0.4 turns); descent: segment 3
    # down by the rise
    assert heights[:5] == pytest.approx([89.0] * 5, abs=0.5)
    assert heights[5:] == pytest.approx([85.0] * 5, abs=0.3)


def test_commands_cover_six_motors_within_their_limits(default_run) -> None:  # type: ignore[no-untyped-def]
    _, _, _, sent = default_run
    for speeds in sent:
        assert set(speeds) == set(MotorId)
        for motor, v in speeds.items():
            limit = CFG.motors.lift_speed if motor in LIFT_MOTORS else CFG.motors.wheel_speed
            assert abs(v) <= limit


def test_approach_stops_approach_gap_before_the_riser() -> None:
    robot = KinematicRobot(CFG, steps=[STEP] * 2)
    ctrl = Controller(CFG)
    gap = CFG.algorithm.approach_gap
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_LIFT_FIRST)
    assert robot.front_x == pytest.approx(-gap, abs=0.002)
    # the second approach starts nearer than SAFE_DISTANCE_IN_FRONT_OF_STEP
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_APPROACH)
    assert STEP[1] - robot.front_x < CFG.SAFE_DISTANCE_IN_FRONT_OF_STEP
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_LIFT_FIRST)
    assert robot.front_x == pytest.approx(STEP[1] - gap, abs=0.002)


def test_a_wall_at_the_top_ends_the_ascent_as_an_obstacle_and_descends() -> None:
    ctrl, robot, events, _ = go(steps=[STEP] * 3, top="wall")
    r = ctrl.result
    assert (r.outcome, r.ascent_end, r.steps_climbed, r.steps_descended) == \
        ("completed", "obstacle", 3, 3)
    seq = phases(events)
    i = seq.index(Phase.ASCENT_LOWER_OBSTACLE)
    assert seq[i + 1] is Phase.DESCENT_BACK_OFF
    assert robot.front_x == pytest.approx(robot.start_front_x, abs=0.003)


TOO_HIGH_MTF = CFG.MAX_OF_VERTICAL_TURNS - CFG.initial_number_of_vertical_turns
"""A step too high: MTF made its whole allowance without seeing over it."""
TOO_SHORT_MTF = CFG.lift_turns(0.17 - CFG.sensors.front_height) \
    + CFG.initial_number_of_vertical_turns
"""A tread too short: seen over at the rise, measured number_of_vertical_turns higher."""


@pytest.mark.parametrize(("step", "mtf"), [((0.25, 0.28), TOO_HIGH_MTF),
                                           ((0.17, 0.22), TOO_SHORT_MTF)],
                         ids=["too_high", "too_short"])
def test_a_step_it_cannot_climb_ends_the_ascent_and_goes_back(step: tuple[float, float],
                                                             mtf: float) -> None:
    robot = KinematicRobot(CFG, steps=[step] * 2)
    ctrl = Controller(CFG)
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_LOWER_OBSTACLE)
    assert robot.counters[MotorId.MTF] == pytest.approx(mtf, abs=0.5)
    run(ctrl, robot)
    r = ctrl.result
    assert (r.outcome, r.ascent_end, r.steps_climbed, r.steps_descended) == \
        ("completed", "obstacle", 0, 0)
    assert robot.counters[MotorId.MTF] == pytest.approx(0.0, abs=0.05)
    assert robot.front_x == pytest.approx(robot.start_front_x, abs=0.003)


def test_more_steps_than_max_steps_ends_at_the_step_limit() -> None:
    ctrl, robot, _, _ = go(steps=[STEP] * 12)
    r = ctrl.result
    assert (r.outcome, r.ascent_end, r.steps_climbed, r.steps_descended) == \
        ("completed", "step_limit", 10, 10)
    assert robot.front_x == pytest.approx(robot.start_front_x, abs=0.003)


def test_nothing_ahead_is_case_1_and_stops_without_moving() -> None:
    ctrl, _, events, sent = go(steps=[])
    r = ctrl.result
    assert (r.outcome, r.ascent_end, r.error) == ("stopped", None, None)
    assert r.reason is not None and r.reason.startswith("nothing ahead")
    assert ctrl.context.family_of(Calibration).case is CalibrationCase.ONE
    assert all(v == 0.0 for speeds in sent for v in speeds.values())
    assert "nothing ahead" in events[-1].message


def test_calibrate_only_ends_after_the_first_calibration() -> None:
    ctrl, robot, events, _ = go(mode=Mode.CALIBRATE_ONLY, yaw_deg=8.0)
    r = ctrl.result
    assert (r.outcome, r.ascent_end, r.steps_climbed) == ("completed", None, 0)
    assert phases(events)[-3:-1] == [Phase.CAL_LOWER, Phase.CAL_CHECK]  # lowered, checked
    assert abs(robot.yaw) < 0.01
    assert ctrl.context.start.reading == pytest.approx(0.5, abs=0.01)


@pytest.mark.parametrize("yaw", [12.0, -12.0])
def test_noisy_sensors_and_a_yawed_start_still_climb_and_return(yaw: float) -> None:
    ctrl, robot, _, _ = go(steps=[STEP] * 2, yaw_deg=yaw, noise=0.001, seed=5)
    r = ctrl.result
    assert (r.outcome, r.ascent_end, r.steps_climbed, r.steps_descended, r.pauses) == \
        ("completed", "top_reached", 2, 2, 0)
    # square within what "SFR = SFL" can tell: equal_tolerance over the sensors' spacing
    assert abs(robot.yaw) < CFG.algorithm.equal_tolerance / (2 * CFG.sensors.front_lateral)
