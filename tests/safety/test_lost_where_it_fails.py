"""A sensor the present phase does not read, lost on the stairs (issue 33,
limp home): the robot stops where the sensor failed, not a step or a
flight later where a phase reads it.  The way home needs both pairs (the
front reads the risers and treads, the back finds each edge), so past the
start's calibration every distance sensor in error stands the robot.

* Both back sensors lost in ascent 7 of step 1: the robot stays stopped
  there, stranded (nothing finds the edges on the way down), rather than
  climbing the flight and stopping on the top tread.
* One back sensor lost in step 1's ascent: it finishes step 1 and comes
  down it on the other, rather than climbing step 2 first."""

from __future__ import annotations

from lost_sensor import degraded, home, sweep_flight
from simrun import run_sim

from stairbot.control.robot_config import load_config
from stairbot.events import Event
from stairbot.inputs.scenario import parse_scenario
from stairbot.run.runner import RunResult

CONFIG = load_config()
ASCENT_7 = 42.0
"""Ascent 7 of step 1 (segment 3 rising) in the fault-free run of the flight."""


def run(text: str) -> tuple[RunResult, list[Event]]:
    events: list[Event] = []
    r = run_sim(CONFIG, parse_scenario(text, "<lost where it fails>"), events, limp_home=True)
    return r, events


def test_both_back_sensors_lost_in_ascent_7_stay_stopped_there() -> None:
    text = sweep_flight(5, ASCENT_7, "SBR", 'kind = "error"')
    text += f'[[faults]]\nat = {ASCENT_7}\nsensor = "SBL"\nkind = "error"\n'
    r, events = run(text)
    assert r.outcome == "error" and not r.fell, r.to_dict()
    stop = degraded(events)
    assert (stop["lost"], stop["then"], stop["phase"]) == (
        ["SBL", "SBR"], "stranded", "ascent_lift_third"), stop
    assert "both back sensors lost" in stop["why"], stop
    assert r.steps_climbed == 0, r.to_dict()


def test_a_back_sensor_lost_in_step_1s_ascent_comes_home_after_step_1() -> None:
    # case 731 of sweeps/sensor_faults.toml: SBR stuck from 28.5 s
    r, events = run(sweep_flight(272717, 28.5, "SBR", 'kind = "stuck"'))
    assert r.outcome == "came_home_degraded" and home(r), r.to_dict()
    stop = degraded(events)
    assert (stop["lost"], stop["survivors"], stop["then"]) == (["SBR"], ["SBL"], "limp_home")
    assert stop["steps_climbed"] == 0 and stop["phase"].startswith("ascent"), stop
    assert r.steps_climbed == r.steps_descended == 1, r.to_dict()
