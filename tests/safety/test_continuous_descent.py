"""Continuous descent (issue 13): set down on the top of a flight it has not
climbed, the robot backs down to the floor, and refuses what it cannot
descend -- a drop deeper than its lift, a tread shorter than itself --
stopping on the stairs with nothing moving, never falling."""

from __future__ import annotations

import pytest
import simrun

from stairbot.control.algorithm.phases import Mode
from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind
from stairbot.hardware import MotorId
from stairbot.inputs.scenario import parse_scenario
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import run

CONFIG = load_config()


def end_of(events: list[Event]) -> str:
    return next(e.message for e in reversed(events) if e.kind is EventKind.END)


def top(stairs: str, distance: float = 0.1, extra: str = "") -> str:
    return f"[stairs]\n{stairs}\n[start]\non = 'top'\ndistance = {distance}\n{extra}"


@pytest.mark.parametrize("robot", ["default", "ideal", "sonar", "ir"])
def test_from_the_top_of_four_steps_to_the_floor_on_every_shipped_robot(robot: str) -> None:
    config = load_config(None if robot == "default" else robot)
    scenario = parse_scenario(top("count = 4\nrise = 0.17\ntread = 0.3",
                                  extra="yaw_deg = 3.0\n"), "top.toml")
    result = simrun.run_sim(config, scenario)
    assert (result.outcome, result.steps_climbed, result.steps_descended) == (
        "completed", 0, 4), result.to_dict()
    assert not result.fell
    # the whole robot on the floor, clear of the first riser
    assert result.clear_of_stairs_m is not None and result.clear_of_stairs_m > 0.1


@pytest.mark.parametrize(("rise", "robot", "why"), [
    (0.25, "default", "deeper than segment 3 can be lowered"),
    (0.98, "ideal", "nothing within SBR/SBL's range")])
def test_a_drop_deeper_than_the_lift_is_refused_before_it_moves_and_the_robot_backs_on(
        rise: float, robot: str, why: str) -> None:
    """The third step down drops ``rise``: read (0.25 m), or beyond the back
    pair's 1 m range (0.98 m and BACK_CLEARANCE, one level ray each; the
    VL53L0X's cone reads the riser's foot nearer).  Refused: segment 3 back
    up where descent 2 began and the robot forward onto the step, stopped."""
    config = load_config(None if robot == "default" else robot)
    scenario = parse_scenario(top(f"steps = [{{rise = {rise}, tread = 0.3}}, "
                                  "{rise = 0.17, tread = 0.3}, {rise = 0.17, tread = 0.3}]"),
                              "deep.toml")
    events: list[Event] = []
    session = open_robot("sim://", config, RobotOptions(world=scenario))
    try:
        result = run(session, config, events.append, Mode.DESCEND)
        snap = session.robot.read()
    finally:
        session.close()
    assert (result.outcome, result.steps_descended, result.fell) == ("stopped", 2, False)
    refusal = [str(e.data.get("why")) for e in events if e.kind is EventKind.PHASE
               and e.data.get("phase") == "descent_refuse"]
    assert len(refusal) == 1 and why in refusal[0], refusal
    # descent 2 never lowered segment 3 (a read drop): MTB where it began, near 0
    assert snap.turns(MotorId.MTB) == pytest.approx(0.0, abs=0.5)
    assert result.max_pitch_deg is not None and result.max_pitch_deg < 5.0


def test_a_tread_shorter_than_the_robot_is_refused_on_it() -> None:
    """0.20 m treads under a 0.225 m robot: one step down, the back pair
    already reads past the next edge and the floor is not found again in
    front of it: stopped there, not fallen."""
    scenario = parse_scenario(top("count = 3\nrise = 0.17\ntread = 0.20"), "short.toml")
    events: list[Event] = []
    result = simrun.run_sim(CONFIG, scenario, events)
    assert (result.outcome, result.steps_descended, result.fell) == ("stopped", 1, False)
    assert "the tread is shorter than the robot" in end_of(events)
    assert result.max_pitch_deg is not None and result.max_pitch_deg < 15.0


def test_no_edge_within_reach_of_the_start_is_stopped_not_searched_for_ever() -> None:
    scenario = parse_scenario(top("count = 2\nrise = 0.17\ntread = 0.28", distance=1.6),
                              "far.toml")
    events: list[Event] = []
    result = simrun.run_sim(CONFIG, scenario, events)
    assert (result.outcome, result.steps_descended) == ("stopped", 0)
    assert "not on the top of a flight" in end_of(events)


@pytest.mark.parametrize("yaw", [13.0, -20.0])
def test_set_down_askew_it_squares_up_to_the_edge_with_its_back_pair(yaw: float) -> None:
    """Set down 13 deg askew, the robot placed the edge where the second back
    sensor crossed it, backed the clearance and went over on the first one's
    side (the red team: +15.5 deg, then a fall).  It now turns square by how
    far it backed between the two reading the drop."""
    scenario = parse_scenario(top("count = 3\nrise = 0.17\ntread = 0.28",
                                  extra=f"yaw_deg = {yaw}\n"), "askew.toml")
    events: list[Event] = []
    result = simrun.run_sim(CONFIG, scenario, events)
    assert (result.outcome, result.steps_descended, result.fell) == ("completed", 3, False)
    squares = [e.message for e in events if "to square up" in e.message]
    assert len(squares) >= 1
    assert ("turning left" if yaw < 0 else "turning right") in squares[0]
    assert result.max_pitch_deg is not None and result.max_pitch_deg < 5.0


def test_too_far_askew_it_stops_at_the_edge() -> None:
    scenario = parse_scenario(top("count = 3\nrise = 0.17\ntread = 0.28",
                                  extra="yaw_deg = 32.0\n"), "askew.toml")
    result = simrun.run_sim(CONFIG, scenario)
    assert (result.outcome, result.steps_descended, result.fell) == ("error", 0, False)
    assert "turned too far from the edge" in (result.error or "")


@pytest.mark.parametrize("kind", ["error", "freeze"])
def test_a_back_sensor_that_fails_backing_to_the_top_edge_stops_the_robot_before_it(
        kind: str) -> None:
    """SBR failing 0.5 s in hid the edge (the edge is where both read the
    drop): the robot backed over it and fell after the tilt stop (the red
    team).  The back pair is now needed in descent 1: the robot stands, then
    ends, and stands where it stopped."""
    scenario = parse_scenario(top("count = 5", extra=(
        f"[[faults]]\nat = 0.5\nsensor = 'SBR'\nkind = '{kind}'\n")), "fault.toml")
    session = open_robot("sim://", CONFIG, RobotOptions(world=scenario))
    try:
        result = run(session, CONFIG, mode=Mode.DESCEND)
        for _ in range(100):  # two seconds on: it stays where it stopped
            session.clock.advance(CONFIG.algorithm.tick)
            session.robot.read()
    finally:
        session.close()
    assert (result.outcome, result.steps_descended, result.fell) == ("error", 0, False)
    assert "SBR" in (result.error or "") and "descent 1" in (result.error or "")
    assert result.clear_of_stairs_m is not None and result.clear_of_stairs_m < -0.3


@pytest.mark.parametrize("rise", [0.03, 0.05])
def test_low_rises_are_seen_from_the_top(rise: float) -> None:
    """Rises under half min_step_rise_m were not seen as edges and the robot
    backed off them wheels first (the red team: 0.03-0.065 m tipped it)."""
    scenario = parse_scenario(top(f"count = 4\nrise = {rise}\ntread = 0.3"), "low.toml")
    result = simrun.run_sim(CONFIG, scenario)
    assert (result.outcome, result.steps_descended, result.fell) == ("completed", 4, False)
    assert result.clear_of_stairs_m is not None and result.clear_of_stairs_m > 0.1
