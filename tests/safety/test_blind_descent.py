"""A front bias no evidence names where the front pair steered (issue 33,
"limp home"): SFR and SFL still disagree after the standing rule's wait in
descent 1 to 6 of a climbed step, or in ascent 5 to 7, and neither an
onset nor the riser the odometer places says which reads wrong.  Neither is
trusted (:mod:`~stairbot.control.algorithm.blind`); with the operator's
consent the robot finishes the step in progress by counts and goes down
without any front reading: the back-off and descent 3 and 5 by the seed's
turns, descent 1's calibration a turn back to the heading the step was
climbed with by the odometer, the edge found by the back pair, then home by
the odometer.  Where the way home needs the front pair, the stop says why.
The scenarios are cases of sweeps/sensor_faults.toml on the reference robot
(their index in the names); before this each ended stranded by the standing
rule."""

from __future__ import annotations

from lost_sensor import degraded
from test_bias import flight, home, run

from stairbot.control.algorithm import blind, standing
from stairbot.control.algorithm.context import Context, Pause
from stairbot.control.algorithm.families import Calibration
from stairbot.control.algorithm.modes import Purpose
from stairbot.control.algorithm.phase import FAILED, Tick
from stairbot.control.algorithm.phases import Mode, Phase
from stairbot.control.algorithm.work import Work
from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind
from stairbot.hardware import MotorId, MotorState, SensorId, SensorReading, Snapshot


def _after_stop(events: list[Event]) -> tuple[list[str], list[str]]:
    """The phases entered and the info messages said after the degraded stop."""
    stopped = next(e.time_s for e in events if "degraded" in e.data)
    phases = [str(e.data["phase"]) for e in events
              if e.kind is EventKind.PHASE and e.time_s >= stopped]
    infos = [e.message for e in events if e.kind is EventKind.INFO and e.time_s >= stopped]
    return phases, infos


def test_a_front_bias_nothing_names_in_descent_1_goes_down_by_the_back_pair() -> None:
    # case 281: SFR 1 cm long from 75.1 s; the pair disagrees backing off
    # the first step (descent 1 of step 1), where it used to square up to
    # the riser and place the robot by the tab
    r, events = run(flight(87196, 75.1, "SFR", 0.01))
    assert home(r) and r.steps_climbed == 2, r.to_dict()
    stop = degraded(events)
    assert (stop["lost"], stop["biased"], stop["then"], stop["phase"]) == (
        ["SFL", "SFR"], [], "limp_home", "descent_back_off"), stop
    assert stop["plan"].startswith("down the steps climbed without the front pair"), stop
    phases, infos = _after_stop(events)
    # no squaring turn on the pair: the odometer's heading, then the back pair's edge
    assert "cal_turn" not in phases, phases
    assert phases.index("cal_check") < phases.index("descent_back_to_edge") \
        < phases.index("descent_lower_third"), phases
    assert [m for m in infos if "squared by the odometer" in m], infos
    # neither front sensor stands in for the other
    assert not [m for m in infos if "'s value" in m], infos


def test_a_front_bias_nothing_names_in_descent_4_goes_on_down_by_counts() -> None:
    # case 321: SFL 1 cm long from 108.7 s; the pair disagrees lowering
    # segment 2 in descent 4 of the last step down (step 1)
    r, events = run(flight(61857, 108.7, "SFL", 0.01))
    assert home(r) and r.steps_climbed == 2, r.to_dict()
    stop = degraded(events)
    assert (stop["lost"], stop["then"], stop["phase"]) == (
        ["SFL", "SFR"], "limp_home", "descent_lower_second"), stop
    phases, _ = _after_stop(events)
    assert phases[:4] == ["descent_lower_second", "descent_drive_first", "descent_lower_first",
                          "descent_finish"], phases
    assert "cal_turn" not in phases, phases


def test_a_front_bias_nothing_names_in_ascent_5_finishes_the_step_by_counts() -> None:
    # case 270: SFR 1 cm long from 33.5 s; the pair disagrees lifting
    # segment 2 onto the first step (ascent 5)
    r, events = run(flight(459971, 33.5, "SFR", 0.01))
    assert home(r) and r.steps_climbed == 1, r.to_dict()
    assert r.max_pitch_deg is not None and r.max_pitch_deg < 5.0, r.to_dict()
    stop = degraded(events)
    assert (stop["lost"], stop["then"], stop["phase"]) == (
        ["SFL", "SFR"], "limp_home", "ascent_lift_second"), stop
    assert stop["plan"].startswith("finishing the step by counts"), stop
    phases, infos = _after_stop(events)
    assert phases[phases.index("ascent_drive_second"):][:3] == [
        "ascent_drive_second", "ascent_lift_third", "ascent_check"], phases
    # no tab read by a distrusted pair: its step's descent drives by turns
    assert [m for m in infos if "not measurable (the front pair distrusted)" in m], infos


def test_where_the_way_home_needs_the_front_pair_the_stop_says_why() -> None:
    ctx = Context()
    ctx.start.wheel, ctx.number_of_steps = 0.0, 1
    assert "heading step 1 was climbed with" in str(blind.why_not(Phase.DESCENT_LOWER_SECOND,
                                                                  ctx))
    ctx.climb_twist[0] = 0.0
    assert blind.why_not(Phase.DESCENT_LOWER_SECOND, ctx) is None
    assert blind.why_not(Phase.ASCENT_CHECK, ctx) is None  # step 1 counted, its heading kept
    assert "heading step 2" in str(blind.why_not(Phase.ASCENT_LIFT_SECOND, ctx))
    ctx.family = Calibration(purpose=Purpose.DESCENT)
    assert blind.why_not(Phase.CAL_CHECK, ctx) is None
    assert "squaring turn" in str(blind.why_not(Phase.CAL_TURN, ctx))
    assert "front pair places the robot" in str(blind.why_not(Phase.ASCENT_APPROACH, ctx))
    assert "ascent 4 of a later step" in str(blind.why_not(Phase.ASCENT_DRIVE_FIRST, ctx))
    ctx.from_top = True
    assert "continuous descent" in str(blind.why_not(Phase.DESCENT_LOWER_SECOND, ctx))


def _end_of_wait(resume: Phase, ctx: Context) -> str:
    """The standing rule's end, SFL reading 2 cm more than SFR all through
    its wait in ``resume``: the error it ends the program with."""
    cfg = load_config("reference")
    ctx.phase = Phase.PAUSED.value
    ctx.pause = Pause(resume.value, 0.0, [0.02] * 50)
    ctx.watch.ticks = standing.DEBOUNCE_TICKS - 1
    motors = {m: MotorState(0.0) for m in MotorId}
    snap = Snapshot(cfg.algorithm.standing_wait + 0.1,
                    {SensorId.SFR: SensorReading(0.20), SensorId.SFL: SensorReading(0.22),
                     SensorId.SBR: SensorReading(0.2), SensorId.SBL: SensorReading(0.2)},
                    motors)
    step = standing.PAUSED.step
    assert step is not None
    ended = step(Tick(snap, cfg, ctx, Mode.FULL, lambda *a, **k: None), Work.at_entry(snap))
    assert ended.happened == FAILED, ended
    return str(ended.reason)


def test_the_standing_rules_end_says_why_the_way_home_needs_the_front_pair() -> None:
    ctx = Context()
    ctx.start.wheel, ctx.number_of_steps, ctx.climb_twist[0] = 0.0, 1, 0.0
    said = _end_of_wait(Phase.ASCENT_APPROACH, ctx)
    assert said.startswith("standing rule: SFR/SFL still disagree"), said
    assert "the way home from here needs the front pair (ascent 2" in said, said
    assert said.endswith("the remaining sensors cannot support a descent"), said
