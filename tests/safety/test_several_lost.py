"""Several sensors lost at once (issue 33): the degraded stop counts every
distance sensor in error at the moment of the stop, not only those the
present phase needs.  In ascent 7 (42 s of the two-step flight) the phase
needs the front pair alone, and the way home from there needs the back pair
(descent 2 on finds the edges by it): with SFR and both back sensors lost
the robot stays stopped where it stands and says why; with SFR and one back
sensor lost each pair keeps a survivor, and one stop names both and limps
home."""

from __future__ import annotations

from lost_sensor import degraded, home, sweep_flight
from simrun import run_sim

from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind
from stairbot.inputs.scenario import parse_scenario
from stairbot.run.runner import RunResult

CONFIG = load_config()
AT = 42.0
"""Ascent 7 of step 1 (segment 3 rising) in the fault-free run of the flight."""


def flight(*faults: tuple[str, float | None]) -> str:
    """The two-step flight with SFR erring from AT on, and each (sensor,
    duration) of ``faults`` erring from AT too (for the rest of the run where
    the duration is None)."""
    text = sweep_flight(5, AT, "SFR", 'kind = "error"')
    for sensor, duration in faults:
        text += f'[[faults]]\nat = {AT}\nsensor = "{sensor}"\nkind = "error"\n'
        if duration is not None:
            text += f"duration = {duration}\n"
    return text


def run(text: str) -> tuple[RunResult, list[Event]]:
    events: list[Event] = []
    r = run_sim(CONFIG, parse_scenario(text, "<several lost>"), events, limp_home=True)
    return r, events


def phases_after(events: list[Event], time_s: float) -> list[str]:
    return [str(e.data["phase"]) for e in events
            if e.kind is EventKind.PHASE and e.time_s >= time_s]


def test_a_front_sensor_and_both_back_sensors_lost_at_once_stay_stopped_and_say_why() -> None:
    r, events = run(flight(("SBR", None), ("SBL", None)))
    assert r.outcome == "error" and not r.fell, r.to_dict()
    stop = degraded(events)
    assert (stop["lost"], stop["then"], stop["phase"]) == (
        ["SBL", "SBR", "SFR"], "stranded", "ascent_lift_third"), stop
    assert all(s in stop["failed"] for s in ("SFR", "SBR", "SBL")), stop
    assert "both back sensors lost" in stop["why"] and stop["plan"] == "", stop
    assert r.error is not None and "both back sensors lost" in r.error, r.error
    assert all(s in r.error for s in ("SFR", "SBR", "SBL")), r.error
    # stopped where it stood: step 1 not finished, nothing after the stop
    assert r.steps_climbed == 0 and phases_after(events, AT) == ["error"], r.to_dict()


def test_a_front_and_a_back_sensor_lost_at_once_come_home_on_one_of_each_pair() -> None:
    r, events = run(flight(("SBL", None)))
    assert r.outcome == "came_home_degraded" and home(r), r.to_dict()
    stop = degraded(events)  # one stop for both, not a second one in descent 2
    assert (stop["lost"], stop["survivors"], stop["then"]) == (
        ["SBL", "SFR"], ["SBR", "SFL"], "limp_home"), stop
    assert "SFR" in stop["failed"] and "SBL" in stop["failed"], stop
    assert "finishing step 1" in stop["why"], stop


def test_back_sensors_back_before_the_hold_ends_are_not_lost() -> None:
    """A guard, not a regression (it passes before the change too): a sensor
    the phase does not need that errs for less than the hold's wait is read
    again when the robot decides, and is not counted."""
    r, events = run(flight(("SBR", 0.5), ("SBL", 0.5)))
    assert r.outcome == "came_home_degraded" and home(r), r.to_dict()
    stop = degraded(events)
    assert (stop["lost"], stop["survivors"], stop["then"]) == (["SFR"], ["SFL"], "limp_home")
