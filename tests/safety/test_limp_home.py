"""Limp home (issue 33): a distance sensor lost on the stairs stops the robot,
lifts holding, and it says what failed and where it stands; with the
operator's consent it finishes or undoes the step in progress and comes
back down on the sensors that remain, at LIMP_SPEED, ending
``came_home_degraded``.  Without consent, or with both sensors of a pair
gone, it stays stopped and says why.  Faults at robot times that fall in
the named phases of a fault-free run of the same stairs."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from lost_sensor import TWO_STEPS, degraded, home
from simrun import run_sim

from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.limp import LIMP_SPEED
from stairbot.control.algorithm.lost import awaits_consent
from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind
from stairbot.hardware import WHEEL_MOTORS, Snapshot, Speeds
from stairbot.inputs.scenario import parse_scenario
from stairbot.run import runner
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import RunResult

CONFIG = load_config()


def faulted(*faults: tuple[float, str, str]) -> str:
    """TWO_STEPS with a fault (at, sensor, kind) for the rest of the run each."""
    return TWO_STEPS + "".join(f'[[faults]]\nat = {at}\nsensor = "{sensor}"\nkind = "{kind}"\n'
                               for at, sensor, kind in faults)


def run(text: str, *, consent: bool = True,
        tap: Any = None) -> tuple[RunResult, list[Event]]:
    events: list[Event] = []
    r = run_sim(CONFIG, parse_scenario(text, "<limp>"), events, limp_home=consent, tap=tap)
    return r, events



def phases_after(events: list[Event], time_s: float) -> list[str]:
    return [str(e.data["phase"]) for e in events
            if e.kind is EventKind.PHASE and e.time_s >= time_s]



def test_a_front_sensor_lost_lifting_segment_3_finishes_the_step_and_comes_home() -> None:
    r, events = run(faulted((42.0, "SFR", "error")))  # ascent 7 of step 1
    assert (r.outcome, r.ascent_end, r.steps_climbed) == (
        "came_home_degraded", "sensor_lost", 1), r.to_dict()
    assert home(r), r.to_dict()
    stop = degraded(events)
    assert (stop["lost"], stop["survivors"], stop["then"]) == (["SFR"], ["SFL"], "limp_home")
    assert stop["phase"] == "ascent_lift_third" and stop["where"] == "step 1"
    assert set(stop["lifts"]) == {"MTF", "MTB"}
    assert "finishing step 1" in stop["why"], stop
    # the step finished, then straight down it: no approach to step 2
    after = phases_after(events, 42.0)
    assert after[:2] == ["ascent_check", "descent_lower_third"], after


def test_a_front_sensor_lost_lifting_segment_1_undoes_the_step() -> None:
    r, events = run(faulted((56.0, "SFL", "freeze")))  # ascent 3 of step 2
    assert (r.outcome, r.steps_climbed, r.steps_descended) == (
        "came_home_degraded", 1, 1), r.to_dict()
    assert home(r), r.to_dict()
    assert "undoing step 2" in degraded(events)["why"]
    after = phases_after(events, 56.0)
    assert after[:2] == ["ascent_lower_obstacle", "descent_back_off"], after


def test_a_front_sensor_lost_on_the_first_approach_backs_to_the_start() -> None:
    r, events = run(faulted((14.5, "SFR", "error")))
    assert (r.outcome, r.steps_climbed) == ("came_home_degraded", 0), r.to_dict()
    assert home(r), r.to_dict()
    assert phases_after(events, 14.5)[0] == "descent_finish"


def test_a_back_sensor_lost_backing_to_the_edge_comes_down_on_the_other() -> None:
    r, events = run(faulted((111.1, "SBR", "error")))  # descent 1 of step 1
    assert (r.outcome, r.ascent_end, r.steps_climbed) == (
        "came_home_degraded", "top_reached", 2), r.to_dict()
    assert home(r), r.to_dict()
    assert degraded(events)["survivors"] == ["SBL"]


def test_limping_home_runs_every_motor_at_limp_speed_at_most() -> None:
    fastest: dict[str, float] = {"before": 0.0, "after": 0.0}

    def tap(snap: Snapshot, sent: Speeds | None) -> None:
        if sent:
            key = "after" if snap.time_s > 44.0 else "before"
            wheels = max(abs(sent.get(m, 0.0)) for m in WHEEL_MOTORS)
            fastest[key] = max(fastest[key], wheels)

    r, _events = run(faulted((42.0, "SFR", "error")), tap=tap)
    assert r.outcome == "came_home_degraded", r.to_dict()
    top = CONFIG.motors.wheel_speed
    assert fastest["before"] > LIMP_SPEED * top * 1.5
    assert 0.0 < fastest["after"] <= LIMP_SPEED * top + 1e-9


def test_without_consent_the_robot_stays_stopped_and_says_it_could_come_down() -> None:
    r, events = run(faulted((42.0, "SFR", "error")), consent=False)
    assert r.outcome == "error" and not r.fell, r.to_dict()
    assert r.error is not None and r.error.startswith("sensor error: SFR"), r.error
    assert "operator's consent" in r.error and r.awaits_consent, r.to_dict()
    assert "stairbot run" not in r.error  # how to consent is the front end's to say
    assert degraded(events)["then"] == "no_consent"
    assert phases_after(events, 42.0)[-1] == "error"


def test_both_back_sensors_lost_stay_stopped_and_say_why() -> None:
    r, events = run(faulted((111.1, "SBR", "error"), (111.1, "SBL", "error")))
    assert r.outcome == "error" and not r.fell and r.steps_descended == 1, r.to_dict()
    assert r.error is not None and "both back sensors lost" in r.error, r.error
    stop = degraded(events)
    assert (stop["then"], stop["lost"]) == ("stranded", ["SBL", "SBR"])


def test_the_second_back_sensor_lost_while_limping_stays_stopped() -> None:
    r, events = run(faulted((111.1, "SBR", "error"), (126.0, "SBL", "error")))
    assert r.outcome == "error" and not r.fell, r.to_dict()
    assert r.error is not None and "both back sensors lost" in r.error, r.error
    stops = [e.data["degraded"]["then"] for e in events if "degraded" in e.data]
    assert stops == ["limp_home", "stranded"]


def test_a_sensor_lost_before_the_start_is_measured_ends_the_run_as_before() -> None:
    r, events = run(faulted((0.0, "SFR", "error")))
    assert r.outcome == "error" and r.steps_climbed == 0, r.to_dict()
    assert r.final_offset_m is not None and r.final_offset_m < 0.01, r.to_dict()
    assert not [e for e in events if "degraded" in e.data]


def test_a_sensor_lost_squaring_up_after_closing_in_backs_to_where_it_began() -> None:
    r, events = run(faulted((7.0, "SFR", "error")))  # calibration's case-2 turn
    assert (r.outcome, r.steps_climbed) == ("came_home_degraded", 0), r.to_dict()
    assert home(r), r.to_dict()
    after = phases_after(events, 7.0)
    assert after[after.index("cal_check") + 1] == "descent_finish", after
    infos = [e.message for e in events if e.kind is EventKind.INFO and e.time_s > 8.2]
    assert infos and all(m.endswith("[limping: SFR reads SFL's value]") for m in infos)


def test_a_sensor_of_the_other_pair_lost_while_limping_limps_on_with_both_stand_ins() -> None:
    r, events = run(faulted((42.0, "SFR", "error"), (58.0, "SBL", "freeze")))
    assert r.outcome == "came_home_degraded" and home(r), r.to_dict()
    stops = [e.data["degraded"] for e in events if "degraded" in e.data]
    assert [(s["lost"], s["then"]) for s in stops] == [
        (["SFR"], "limp_home"), (["SBL", "SFR"], "limp_home")]
    assert stops[1]["survivors"] == ["SBR", "SFL"]


def test_a_program_reopened_to_limp_home_says_so_at_its_first_tick() -> None:
    """The consent after the stop (a resume, the console's question) reopens
    the program: the event that says so carries the time it was given, not
    the time the stopped phase began (as it was stamped before)."""
    snaps: list[Snapshot] = []
    ended: list[Controller] = []
    session = open_robot("sim://", CONFIG, RobotOptions(
        world=parse_scenario(faulted((42.0, "SFR", "error")), "<limp>")))
    try:
        runner.run(session, CONFIG, on_tick=lambda ctl, snap: ended.append(ctl),
                   tap=lambda snap, sent: snaps.append(snap))
    finally:
        session.close()
    assert awaits_consent(ended[-1].context)
    later = replace(snaps[-1], time_s=snaps[-1].time_s + 5.0)
    events: list[Event] = []
    reopened = Controller(CONFIG, events.append, context=ended[-1].context, limp_home=True)
    reopened.tick(later)
    said = [e for e in events if e.kind is EventKind.RESUME]
    assert [(e.time_s, e.message.split(":")[0]) for e in said] == [
        (later.time_s, "limp home (consented on resuming)")], events
