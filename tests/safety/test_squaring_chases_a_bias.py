"""A squaring turn that chases a front sensor's offset (issue 33, "limp
home"): a constant offset moves with the turn as a healthy reading does, so
calibration turned until SFR = SFL, 17 deg askew of the riser for 3 cm, or
on the sonar robot until both beams met the riser too obliquely to hear an
echo, and "squared up over 0 readings".  On a climbed step the odometer
knows the heading the step was climbed with, squared to a parallel riser:
descent 1's turn that goes further from it than both squarings and the
odometer's drift over the step allow, or loses both beams, turns back to
it; elsewhere a turn that lost both beams turns back to where it began.
Back there, the sensor whose reading changed while its partner's did not
is judged biased; if neither, descent 1 distrusts the front pair.  The
scenarios are cases of sweeps/sensor_faults.toml (their index in the
names)."""

from __future__ import annotations

from lost_sensor import degraded
from simrun import run_sim
from test_bias import CONFIG, flight, home

from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import parse_scenario
from stairbot.run.runner import RunResult

SONAR = load_config("sonar")


def _run(cfg: RobotConfig, text: str) -> tuple[RunResult, list[Event]]:
    events: list[Event] = []
    return run_sim(cfg, parse_scenario(text, "<chased>"), events, limp_home=True), events


def _turned_back_then_distrusted(events: list[Event]) -> None:
    """Descent 1's squaring turn was found chasing an offset, the robot
    turned back to the climbed heading by the odometer and lowered, and
    only then were both front sensors lost: no descent askew."""
    infos = [e for e in events if e.kind is EventKind.INFO]
    chased = [e for e in infos if e.message.startswith("descent 1, step 1: the squaring turn")]
    assert len(chased) == 1, [e.message for e in infos]
    after = [str(e.data["phase"]) for e in events
             if e.kind is EventKind.PHASE and e.time_s >= chased[0].time_s]
    assert after[:3] == ["cal_turn_to", "cal_lower", "cal_check"], after
    stop = degraded(events)
    assert (stop["lost"], stop["biased"], stop["phase"]) == (["SFL", "SFR"], [], "cal_check"), \
        stop
    assert "chases an offset of one front sensor" in stop["failed"], stop
    # back on the climbed heading, neither reading changed from before the turn
    assert "the offset was there before the turn" in stop["failed"], stop
    assert stop["steps_climbed"] == 2 and stop["steps_descended"] == 1, stop


def test_descent_1_does_not_square_up_to_a_3_cm_front_bias_on_the_reference_robot() -> None:
    # case 452: SFL 3 cm short from 107.7 s, as descent 1 stood on tread 1;
    # the turn squared up to it 17 deg askew, the robot came down that step
    # askew and home 6.9 cm from its start
    r, events = _run(CONFIG, flight(63500, 107.7, "SFL", -0.03))
    assert not r.fell, r.to_dict()
    _turned_back_then_distrusted(events)


def test_descent_1_turns_back_when_the_sonar_pair_loses_both_echoes_chasing_a_bias() -> None:
    # case 445 on sonar: SFL 3 cm short from 70.1 s; descent 1's turn chased
    # it until both echoes were lost, "squared up" over no reading and ended
    # the run askew on tread 1
    r, events = _run(SONAR, flight(619583, 70.1, "SFL", -0.03))
    assert not r.fell, r.to_dict()
    _turned_back_then_distrusted(events)


def test_the_start_s_squaring_that_lost_both_echoes_names_the_sensor_whose_reading_changed(
        ) -> None:
    # case 528 on sonar: SFR 5 cm long from 7.1 s, in the start's squaring
    # turn; it chased the offset until both echoes were lost, "squared up
    # over 0 readings", and the run ended on the floor 9 cm from its start.
    # Back on the heading the turn began from, SFR reads 5 cm more than the
    # check there measured, SFL the same: SFR is lost, and the robot backs
    # home by the odometer
    r, events = _run(SONAR, flight(769884, 7.1, "SFR", 0.05))
    assert home(r) and r.steps_climbed == 0, r.to_dict()
    stop = degraded(events)
    assert (stop["lost"], stop["biased"], stop["survivors"], stop["phase"]) == (
        ["SFR"], ["SFR"], ["SFL"], "cal_check"), stop
    assert "lost both beams" in stop["failed"], stop
    assert "SFR reads 5." in stop["failed"] and "more than it did there" in stop["failed"], stop
