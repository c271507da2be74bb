"""A stuck distance sensor (issue 33): fresh measurements, one value, while
the robot moves what it looks at.  Perception judges it stuck and it reads as
ERROR, so it is lost as an erroring sensor is, and the robot limps home on
its partner.  Before the judgement the host trusted it (it is fresh): a
front sensor stuck lifting segment 3 ended the run on the stairs
(calibration could not square up to the riser on the way down), a back
sensor stuck lowering segment 3 ended it by the standing rule.  Faults at
robot times that fall in the named phases of a fault-free run of the same
stairs (tests/safety/test_limp_home.py)."""

from __future__ import annotations

from typing import Any

from lost_sensor import TWO_STEPS, degraded_stops, home
from simrun import run_sim

from stairbot.control.robot_config import load_config
from stairbot.events import Event
from stairbot.inputs.scenario import parse_scenario
from stairbot.run.runner import RunResult

CONFIG = load_config()


def stuck(at: float, sensor: str, robot: str = "reference") -> tuple[RunResult, dict[str, Any]]:
    """TWO_STEPS with ``sensor`` stuck from ``at`` on, consented: the result
    and the one degraded stop."""
    text = TWO_STEPS + f'[[faults]]\nat = {at}\nsensor = "{sensor}"\nkind = "stuck"\n'
    events: list[Event] = []
    cfg = CONFIG if robot == "reference" else load_config(robot)
    r = run_sim(cfg, parse_scenario(text, "<stuck>"), events, limp_home=True)
    stops = degraded_stops(events)
    assert len(stops) == 1, (r.to_dict(), stops)
    return r, stops[0]



def test_a_front_sensor_stuck_mid_climb_is_lost_and_the_robot_comes_home() -> None:
    r, stop = stuck(42.0, "SFR")  # ascent 7 of step 1: it holds the tab it read
    assert (r.outcome, r.ascent_end, r.steps_climbed) == (
        "came_home_degraded", "sensor_lost", 1), r.to_dict()
    assert home(r), r.to_dict()
    assert (stop["lost"], stop["survivors"], stop["then"]) == (["SFR"], ["SFL"], "limp_home")
    assert stop["failed"].startswith("SFR stuck at 0.1"), stop
    assert "while the drive moved" in stop["failed"] and "toward the riser" in stop["failed"]


def test_a_back_sensor_stuck_lowering_segment_3_is_lost_and_the_robot_comes_home() -> None:
    r, stop = stuck(84.0, "SBR")  # descent 2 of step 2, segment 3 over the edge
    assert (r.outcome, r.steps_climbed) == ("came_home_degraded", 2), r.to_dict()
    assert home(r), r.to_dict()
    assert (stop["lost"], stop["survivors"], stop["phase"]) == (
        ["SBR"], ["SBL"], "descent_lower_third")
    assert stop["failed"].startswith("SBR stuck at 0."), stop
    assert "SBL's reading went from" in stop["failed"] and "as MTB moved" in stop["failed"]


def test_a_front_sensor_stuck_reading_nothing_from_the_top_is_lost_in_descent_1s_turn() -> None:
    # stuck in step 2's climb, it holds "nothing within range" from the top:
    # descent 1's squaring turn on step 1 turned 42 degrees with SFR at
    # 1.300 m throughout while SFL moved, and the run ended on the stairs
    r, stop = stuck(65.0, "SFR")
    assert (r.outcome, r.steps_climbed) == ("came_home_degraded", 2), r.to_dict()
    assert home(r), r.to_dict()
    assert (stop["lost"], stop["survivors"], stop["phase"], stop["then"]) == (
        ["SFR"], ["SFL"], "cal_turn", "limp_home")
    assert stop["failed"].startswith("SFR stuck: read 1.300 m through a turn of"), stop
    assert "while SFL went from" in stop["failed"]


def test_a_front_sonar_stuck_at_nothing_is_lost_when_its_partners_echo_turns_off_the_riser(
        ) -> None:
    # the sonar robot: descent 1's squaring turn toward SFR's side lost SFR's
    # echo off the riser's face before the turn's limit, both then read
    # 1.300 m, "squared up" on no readings, and the run ended on the stairs
    r, stop = stuck(54.1, "SFL", "sonar")
    assert (r.outcome, r.steps_climbed) == ("came_home_degraded", 2), r.to_dict()
    assert home(r), r.to_dict()
    assert (stop["lost"], stop["survivors"], stop["phase"], stop["then"]) == (
        ["SFL"], ["SFR"], "cal_turn", "limp_home")
    assert stop["failed"].startswith("SFL stuck: read 1.300 m through a turn of"), stop
    assert "and then to nothing ahead" in stop["failed"]


def test_a_back_sensor_stuck_on_the_floor_is_lost_when_its_partner_crosses_the_edge() -> None:
    # stuck descending step 2, it holds the floor: descent 1 on step 1 saw
    # SBL read the drop and SBR the floor 48 mm later, the robot square to
    # the edge by the odometer, and the run ended on the stairs
    r, stop = stuck(93.5, "SBR")
    assert (r.outcome, r.steps_climbed) == ("came_home_degraded", 2), r.to_dict()
    assert home(r), r.to_dict()
    assert (stop["lost"], stop["survivors"], stop["then"]) == (["SBR"], ["SBL"], "limp_home")
    assert stop["phase"].startswith("descent_"), stop
    assert stop["failed"].startswith("SBR stuck: still reads the floor"), stop
    assert "after SBL read the drop" in stop["failed"]


def test_a_back_sensor_reading_long_reads_the_drop_early_and_its_partner_is_not_judged() -> None:
    # SBL 5 cm long from descending step 2 reads the drop at step 1's edge
    # early, SBR (right, and noisy) the floor: the edge watch's lag alone
    # does not say which is wrong, and SBR's values do not hold, so SBR is
    # never judged (judged on the lag alone, SBR read as ERROR for a tick,
    # and had it held its value the robot would have limped home on the
    # biased SBL).  The bias watch names SBL by its onset while the robot
    # stood, and the robot comes home on SBR.
    text = TWO_STEPS + '[[faults]]\nat = 93.5\nsensor = "SBL"\nkind = "offset"\noffset = 0.05\n'
    events: list[Event] = []
    r = run_sim(CONFIG, parse_scenario(text, "<long>"), events, limp_home=True)
    assert (r.outcome, r.steps_climbed, r.steps_descended) == (
        "came_home_degraded", 2, 2), r.to_dict()
    assert home(r), r.to_dict()
    stops = degraded_stops(events)
    assert [(s["lost"], s["survivors"]) for s in stops] == [(["SBL"], ["SBR"])], stops
    assert not [e for e in events if "SBR" in e.message and "stuck" in e.message]
