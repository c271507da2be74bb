"""Errors, the standing rule, the operator's hold and abort: the controller
stops safely, says why, and never moves again once it has ended."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest
from kinematic import Fault, KinematicRobot, run

from stairbot.control.algorithm import blocked, guards
from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.guards import PHASE_TIMEOUT_S, SENSOR_WAIT_S, phase_timeout_s
from stairbot.control.algorithm.phases import Phase
from stairbot.control.perception import CONFIRM
from stairbot.control.robot_config import load_config, parse_config
from stairbot.events import Event, EventKind
from stairbot.hardware import LIFT_MOTORS, MotorId, MotorState, SensorId, SensorReading, Snapshot

CFG = load_config("ideal")  # the algorithm's logic, on the readings it was written for
STEPS = [(0.17, 0.28)] * 2
WAIT = CFG.algorithm.standing_wait
TICK = CFG.algorithm.tick


def start(**kw: object) -> tuple[Controller, KinematicRobot, list[Event]]:
    events: list[Event] = []
    kw.setdefault("steps", STEPS)
    return Controller(CFG, events.append), KinematicRobot(CFG, **kw), events  # type: ignore[arg-type]


def of(events: list[Event], kind: EventKind) -> list[Event]:
    return [e for e in events if e.kind is kind]


def still(sent: list[dict[MotorId, float]]) -> bool:
    return all(v == 0.0 for speeds in sent for v in speeds.values())


def finish_and_check_zero(ctrl: Controller, robot: KinematicRobot) -> None:
    """After the end every tick commands zero, whatever the robot reads."""
    assert ctrl.finished
    for _ in range(5):
        speeds = ctrl.tick(robot.read())
        assert speeds == dict.fromkeys(MotorId, 0.0)
        robot.advance(TICK)


def test_a_sensor_error_at_the_start_is_case_1_and_an_error() -> None:
    ctrl, robot, events = start(faults=[Fault(SensorId.SFL, 0.0, error=True)])
    sent = run(ctrl, robot)
    assert ctrl.result.outcome == "error"
    assert ctrl.result.error is not None and "sensor error: SFL" in ctrl.result.error
    assert still(sent)
    assert of(events, EventKind.ERROR) and of(events, EventKind.END)
    finish_and_check_zero(ctrl, robot)


def test_a_sensor_error_mid_ascent_stops_everything() -> None:
    ctrl, robot, _ = start(faults=[Fault(SensorId.SFR, 25.0, error=True)])
    run(ctrl, robot)
    assert ctrl.result.outcome == "error"
    assert "sensor error: SFR" in str(ctrl.result.error)
    # CONFIRM errors in a row make it an error; the robot stands SENSOR_WAIT_S
    # for it to come back, then ends
    assert 25.0 + SENSOR_WAIT_S <= robot.t < 25.0 + SENSOR_WAIT_S + (CONFIRM + 2) * TICK
    finish_and_check_zero(ctrl, robot)


def test_a_passing_sensor_error_holds_the_robot_still_and_it_carries_on() -> None:
    ctrl, robot, events = start(faults=[Fault(SensorId.SFR, 25.0, 25.5, error=True)])
    run(ctrl, robot, until=lambda c: bool(of(events, EventKind.PAUSE)))
    held_in = ctrl.phase
    sent = run(ctrl, robot, until=lambda c: bool(of(events, EventKind.RESUME)))
    assert still(sent[:-1])  # every motor stopped, the lifts holding (the last tick resumed)
    assert ctrl.phase is held_in
    run(ctrl, robot)
    r = ctrl.result
    assert (r.outcome, r.pauses, r.steps_climbed, r.steps_descended) == ("completed", 1, 2, 2)
    assert "SFR" in of(events, EventKind.PAUSE)[0].message


def test_one_error_or_out_of_range_measurement_decides_nothing() -> None:
    faults = [Fault(SensorId.SFR, 20.0 + i * 0.5, 20.0 + i * 0.5 + (CONFIRM - 1) * TICK,
                    error=True) for i in range(20)]
    ctrl, robot, _ = start(faults=faults)
    run(ctrl, robot)
    assert (ctrl.result.outcome, ctrl.result.pauses) == ("completed", 0)


def test_a_frozen_sensor_is_stale_and_the_robot_stops_with_lifts_holding() -> None:
    ctrl, robot, events = start(faults=[Fault(SensorId.SFL, 25.0, freeze=True)])
    sent = run(ctrl, robot)
    assert ctrl.result.outcome == "error"
    assert "SFL stale" in str(ctrl.result.error)
    pause = of(events, EventKind.PAUSE)[0]
    assert 25.0 < pause.time_s < 25.0 + 0.2  # noticed within a few ticks
    assert still(sent[-round(SENSOR_WAIT_S / TICK):])
    finish_and_check_zero(ctrl, robot)


def test_a_back_sensor_in_error_from_the_start_stops_the_robot_before_it_climbs() -> None:
    # the start's calibration reads the front pair alone; from the approach on
    # the way home needs the back pair, and the robot climbs nothing without it
    ctrl, robot, _ = start(faults=[Fault(SensorId.SBL, 0.0, error=True)])
    run(ctrl, robot)
    assert ctrl.result.outcome == "error"
    assert "SBL" in str(ctrl.result.error) and "ascent 2" in str(ctrl.result.error)
    assert ctrl.result.steps_climbed == 0


def test_a_motor_fault_ends_with_an_error_naming_the_motor() -> None:
    ctrl, robot, _ = start()
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_LIFT_FIRST)
    robot.motor_faults[MotorId.MTF] = "overcurrent"
    run(ctrl, robot)
    assert ctrl.result.outcome == "error"
    assert "MTF" in str(ctrl.result.error) and "overcurrent" in str(ctrl.result.error)
    finish_and_check_zero(ctrl, robot)


@pytest.mark.parametrize(("motors", "phase"), [
    ((MotorId.MWR, MotorId.MWL), Phase.ASCENT_APPROACH),  # against something unseen
    ((MotorId.MWF,), Phase.ASCENT_APPROACH),
    ((MotorId.MTF,), Phase.ASCENT_LIFT_FIRST),
    ((MotorId.MTB,), Phase.ASCENT_LIFT_THIRD),
])
def test_a_motor_commanded_that_does_not_turn_is_a_stall_and_everything_stops(
        motors: tuple[MotorId, ...], phase: Phase) -> None:
    ctrl, robot, _ = start()
    run(ctrl, robot, until=lambda c: c.phase is phase)
    robot.jammed.update(motors)
    motor = motors[0]
    jammed_at = robot.t
    run(ctrl, robot)
    assert ctrl.result.outcome == "error"
    assert "stall" in str(ctrl.result.error) and str(motor) in str(ctrl.result.error)
    assert robot.t - jammed_at < 3.0  # noticed within a few seconds, not at the phase timeout
    finish_and_check_zero(ctrl, robot)


def test_floor_not_found_when_descending() -> None:
    # the back sensors see a floor 0.5 m further down than it is: MTB runs out of stroke
    ctrl, robot, _ = start(back_offset=0.5)
    run(ctrl, robot)
    assert ctrl.result.outcome == "error"
    assert "floor not found" in str(ctrl.result.error)
    assert "MAX_OF_VERTICAL_TURNS" in str(ctrl.result.error)
    assert robot.counters[MotorId.MTB] == pytest.approx(-CFG.MAX_OF_VERTICAL_TURNS, abs=0.05)


def test_back_clearance_already_read_before_lowering_is_an_error() -> None:
    ctrl, robot, _ = start(back_offset=-0.3)
    run(ctrl, robot)
    assert ctrl.result.outcome == "error"
    assert "before segment 3 was lowered" in str(ctrl.result.error)
    assert robot.counters[MotorId.MTB] == pytest.approx(0.0, abs=0.05)


def test_a_passing_disagreement_pauses_for_the_wait_and_resumes_where_it_stopped() -> None:
    ctrl, robot, events = start(faults=[Fault(SensorId.SFL, 7.0, 9.0, offset=0.05)])
    run(ctrl, robot, until=lambda c: c.phase is Phase.PAUSED)
    paused_at, stopped_in = robot.t, Phase(ctrl.context.resume_phase)
    assert stopped_in is Phase.ASCENT_APPROACH
    assert ctrl.flow == "ascent" and ctrl.phase.flow == "end"
    sent = run(ctrl, robot, until=lambda c: c.phase is not Phase.PAUSED)
    assert still(sent)
    assert robot.t - paused_at == pytest.approx(WAIT, abs=2 * TICK)
    assert ctrl.phase is stopped_in
    run(ctrl, robot)
    r = ctrl.result
    assert (r.outcome, r.pauses, r.steps_climbed, r.steps_descended) == ("completed", 1, 2, 2)
    assert len(of(events, EventKind.PAUSE)) == len(of(events, EventKind.RESUME)) == 1
    assert robot.front_x == pytest.approx(robot.start_front_x, abs=0.003)


def test_a_lasting_disagreement_no_evidence_explains_ends_with_an_error_after_the_wait() -> None:
    # both sensors jump at once, by as much each way: nothing tells which is wrong
    ctrl, robot, events = start(faults=[Fault(SensorId.SFL, 7.0, offset=0.03),
                                        Fault(SensorId.SFR, 7.0, offset=-0.03)])
    run(ctrl, robot)
    r = ctrl.result
    assert (r.outcome, r.pauses) == ("error", 1)
    assert "still disagree" in str(r.error)
    pause = of(events, EventKind.PAUSE)[0]
    assert of(events, EventKind.ERROR)[0].time_s - pause.time_s == pytest.approx(WAIT, abs=0.1)


def test_a_lasting_disagreement_one_sensor_jumped_into_judges_it_after_the_wait() -> None:
    ctrl, robot, events = start(faults=[Fault(SensorId.SFL, 7.0, offset=0.05)])  # approaching
    run(ctrl, robot)
    r = ctrl.result
    # one pause (the standing rule's); then, without consent, a degraded stop
    assert (r.outcome, r.pauses) == ("error", 1)
    error = str(r.error)
    assert error.startswith("sensor error: SFL judged biased: SFL read 5.0 cm longer"), error
    assert "still disagree" not in error and "for 1 s" not in error
    pause = of(events, EventKind.PAUSE)[0]
    assert of(events, EventKind.ERROR)[0].time_s - pause.time_s == pytest.approx(WAIT, abs=0.1)
    stop = [e.data["degraded"] for e in events if "degraded" in e.data]
    assert [(d["lost"], d["survivors"], d["then"]) for d in stop] == [
        (["SFL"], ["SFR"], "no_consent")]


def test_a_disagreement_shorter_than_the_debounce_does_not_stop() -> None:
    ctrl, robot, _ = start(faults=[Fault(SensorId.SFL, 5.0, 5.0 + 2 * TICK, offset=0.05)])
    run(ctrl, robot)
    assert (ctrl.result.outcome, ctrl.result.pauses) == ("completed", 0)


def test_sensor_noise_alone_does_not_stop_the_robot() -> None:
    ctrl, robot, _ = start(noise=0.002, seed=3, yaw_deg=5.0)
    run(ctrl, robot)
    assert (ctrl.result.outcome, ctrl.result.pauses) == ("completed", 0)


def test_the_back_pair_is_watched_while_segment_3_is_lowered() -> None:
    ctrl, robot, _ = start()
    run(ctrl, robot, until=lambda c: c.phase is Phase.DESCENT_LOWER_THIRD)
    robot.faults.append(Fault(SensorId.SBR, robot.t + 0.5, robot.t + 1.0, offset=0.03))
    run(ctrl, robot, until=lambda c: c.phase is Phase.PAUSED)
    assert ctrl.context.resume_phase == Phase.DESCENT_LOWER_THIRD.value
    run(ctrl, robot)
    assert (ctrl.result.outcome, ctrl.result.pauses) == ("completed", 1)


def test_disagreement_is_not_watched_while_calibration_turns() -> None:
    ctrl, robot, _ = start(yaw_deg=10.0)
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_APPROACH)
    assert ctrl.result.pauses == 0


def test_hold_stops_every_motor_and_freezes_the_timers() -> None:
    ctrl, robot, events = start()
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_LIFT_FIRST)
    ctrl.hold("paused by the operator")
    assert ctrl.held
    held_phase, mtf = ctrl.phase, robot.counters[MotorId.MTF]
    sent = run(ctrl, robot, until=lambda _c: robot.t > 40 + 2 * PHASE_TIMEOUT_S)
    assert still(sent) and ctrl.phase is held_phase  # no timeout while held
    assert robot.counters[MotorId.MTF] == mtf
    ctrl.release()
    assert not ctrl.held
    run(ctrl, robot)
    assert ctrl.result.outcome == "completed"
    assert [e.data.get("held") for e in of(events, EventKind.INFO) if "held" in e.data] == \
        [True, False]


def test_hold_during_the_standing_wait_extends_it() -> None:
    ctrl, robot, _ = start()
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_APPROACH)
    robot.faults.append(Fault(SensorId.SFL, robot.t + 0.2, robot.t + 2.2, offset=0.05))
    run(ctrl, robot, until=lambda c: c.phase is Phase.PAUSED)
    assert ctrl.context.resume_phase == Phase.ASCENT_APPROACH.value
    paused_at = robot.t
    ctrl.hold("operator")
    run(ctrl, robot, until=lambda _c: robot.t > paused_at + 10.0)
    ctrl.release()
    run(ctrl, robot, until=lambda c: c.phase is not Phase.PAUSED)
    assert robot.t - paused_at == pytest.approx(10.0 + WAIT, abs=3 * TICK)


def test_abort_ends_now_with_the_outcome_given() -> None:
    ctrl, robot, events = start()
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_DRIVE_FIRST)
    ctrl.abort("stopped by the operator", "stopped")
    assert ctrl.finished and ctrl.phase is Phase.DONE
    assert ctrl.result.outcome == "stopped" and ctrl.result.error is None
    assert of(events, EventKind.END)[-1].data["outcome"] == "stopped"
    finish_and_check_zero(ctrl, robot)
    ctrl.abort("again", "error")  # no effect once ended
    assert ctrl.result.outcome == "stopped"


def test_abort_with_an_error_and_a_bad_outcome() -> None:
    ctrl, robot, _ = start()
    ctrl.tick(robot.read())
    with pytest.raises(ValueError, match="allowed: completed, stopped, error"):
        ctrl.abort("x", "exploded")
    ctrl.abort("link lost", "error")
    r = ctrl.result
    assert (r.outcome, r.error, ctrl.phase) == ("error", "link lost", Phase.ERROR)


def never_nears(robot: KinematicRobot) -> tuple[float, float]:
    """A riser 0.6 m away that never nears (the wheels slip), read by noisy
    sensors (one value held while the wheels drive is a stuck sensor's)."""
    jitter = 0.001 * (round(robot.t / TICK) % 2)
    return 0.6 + jitter, 0.6 - jitter


@pytest.fixture
def no_blocked_watch(monkeypatch: pytest.MonkeyPatch) -> None:
    """The approach's blocked watch off: wheels that turn while the riser
    never nears are a step below the beams to it, refused long before the
    phase times out (:func:`test_slipping_wheels_end_the_ascent_before_the_phase_timeout`);
    the tests that use this fixture are about the timeout itself."""
    monkeypatch.setattr(blocked, "BLOCKED_M", math.inf)


def test_slipping_wheels_end_the_ascent_before_the_phase_timeout() -> None:
    ctrl, robot, _ = start()
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_APPROACH)
    entered = robot.t
    robot.front_override = never_nears
    run(ctrl, robot)
    r = ctrl.result
    assert (r.outcome, r.ascent_end, r.steps_climbed) == ("completed", "obstacle", 0), r
    assert robot.t - entered < PHASE_TIMEOUT_S


@pytest.mark.usefixtures("no_blocked_watch")
def test_a_phase_that_never_ends_times_out() -> None:
    ctrl, robot, _ = start()
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_APPROACH)
    entered = robot.t
    # wheels turn, the riser never nears (they slip); the readings jitter by
    # a millimetre, as noisy sensors' do: no value repeats to be judged stuck
    robot.front_override = never_nears
    run(ctrl, robot)
    assert "phase timeout" in str(ctrl.result.error)
    assert robot.t - entered == pytest.approx(PHASE_TIMEOUT_S, abs=2 * TICK)


@pytest.mark.usefixtures("no_blocked_watch")
def test_a_phase_timeout_while_the_link_lost_frames_names_the_link() -> None:
    """Found by the real-time soak at 20 % (serial, frames dropped, and
    late): descent 1 ran past the phase timeout on a lossy wire and the
    error said only "took longer than 60 s".  It says what the link counted
    in the phase, and only what it counted after the phase began."""
    ctrl, robot, _ = start()
    read = robot.read
    figures = {"retries": 5.0, "timeouts": 2.0, "lost": 0.0, "revived": 0.0}

    def lossy() -> Snapshot:
        snap = read()
        if ctrl.phase is Phase.ASCENT_APPROACH:
            figures["retries"] += 1
        return replace(snap, health=dict(figures))

    robot.read = lossy  # type: ignore[method-assign]
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_APPROACH)
    robot.front_override = never_nears
    run(ctrl, robot)
    error = str(ctrl.result.error)
    assert error.startswith("phase timeout: ") and "took longer than" in error
    grown = round(figures["retries"] - 5.0)
    assert error.endswith(f"; meanwhile the link lost frames ({grown} retries)"), error


@pytest.mark.usefixtures("no_blocked_watch")
def test_a_phase_timeout_on_a_link_that_lost_nothing_says_nothing_of_it() -> None:
    ctrl, robot, _ = start()
    read = robot.read
    robot.read = lambda: replace(read(), health={"retries": 7.0, "timeouts": 0.0})  # type: ignore[method-assign]
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_APPROACH)
    robot.front_override = never_nears
    run(ctrl, robot)
    error = str(ctrl.result.error)
    assert error.startswith("phase timeout: ") and error.endswith("s"), error
    assert "link" not in error


def test_a_robot_with_slow_lifts_gets_a_longer_phase_timeout() -> None:
    # 2 mm/s lifts take 86 s to lift segment 1 for a step: longer than 60 s
    slow = parse_config('extends = "ideal"\n[motors]\nlift_speed = 1.0\n', "slow")
    assert phase_timeout_s(CFG) == PHASE_TIMEOUT_S
    assert phase_timeout_s(slow) == pytest.approx(2 * 2 * slow.MAX_OF_VERTICAL_TURNS / 1.0)
    ctrl = Controller(slow)
    run(ctrl, KinematicRobot(slow, steps=[(0.17, 0.28)]), max_time=3000.0)
    assert (ctrl.result.outcome, ctrl.result.steps_climbed, ctrl.result.steps_descended) == (
        "completed", 1, 1), ctrl.result


def test_a_turn_that_never_squares_up_ends_with_an_error() -> None:
    def skewed(robot: KinematicRobot) -> tuple[float, float]:
        return 0.5, 0.55  # SFL always 5 cm further: no turn makes them equal

    ctrl, robot, _ = start(front_override=skewed)
    run(ctrl, robot)
    assert ctrl.result.outcome == "error"
    # 5 cm apart at 0.1 m between the mounts: 26.6° askew, and the 12° margin
    assert "more than the 39° its first readings allow" in str(ctrl.result.error)
    assert 38.0 < -math.degrees(robot.yaw) < 40.0  # it stopped there, turned right


def test_readings_too_far_apart_for_one_riser_turn_away_from_the_nearer() -> None:
    """Case 2W: 10 cm apart cannot be one riser within 30°: the nearer (SFR)
    sees a side wall; the robot turns away from it (left) -- never towards
    it -- and ends with an error at 45° when the readings never change."""
    ctrl, robot, events = start(front_override=lambda r: (0.5, 0.6))
    run(ctrl, robot)
    assert any(e.data.get("case") == "2W" for e in events)
    assert ctrl.result.outcome == "error"
    assert "away from the side wall" in str(ctrl.result.error)
    assert 44.0 < math.degrees(robot.yaw) < 47.0  # turned left, as far as allowed
    finish_and_check_zero(ctrl, robot)


def test_a_reading_or_a_counter_that_is_not_a_number_ends_with_an_error() -> None:
    for broken in ("reading", "counter"):
        ctrl, robot, _ = start()
        run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_APPROACH)
        snap = robot.read()
        if broken == "reading":
            sensors = {**snap.sensors, SensorId.SFL: SensorReading(math.nan)}
            snap = Snapshot(snap.time_s, sensors, snap.motors, imu=snap.imu)
        else:
            motors = {**snap.motors, MotorId.MWF: MotorState(math.inf)}
            snap = Snapshot(snap.time_s, snap.sensors, motors, imu=snap.imu)
        assert ctrl.tick(snap) == dict.fromkeys(MotorId, 0.0)
        assert ctrl.result.outcome == "error"
        assert ("SFL" if broken == "reading" else "MWF") in str(ctrl.result.error)
        finish_and_check_zero(ctrl, robot)


def test_a_speed_that_is_not_a_number_is_commanded_as_zero() -> None:
    ctrl, robot, _ = start()
    run(ctrl, robot, until=lambda c: c.phase is Phase.ASCENT_APPROACH)
    vmax = {m: CFG.motors.lift_speed if m in LIFT_MOTORS else CFG.motors.wheel_speed
            for m in MotorId}
    limited = guards.limit_speeds({MotorId.MWF: math.nan, MotorId.MWB: -math.inf,
                                   MotorId.MTF: 99.0}, robot.read(), vmax,
                                  CFG.MAX_OF_VERTICAL_TURNS)
    assert limited[MotorId.MWF] == 0.0 and limited[MotorId.MWB] == 0.0
    assert limited[MotorId.MTF] == CFG.motors.lift_speed


def _descent_3_travel(jump: float) -> tuple[float, list[Event]]:
    ctrl, robot, events = start()
    # step 1's (the top step's has no tab_length_to_edge: it goes by turns anyway)
    run(ctrl, robot, until=lambda c: c.phase is Phase.DESCENT_DRIVE_SECOND
        and c.context.steps_descended == 1)
    at = robot.front_x
    if jump:  # both beams slide onto something further away, at once
        robot.faults += [Fault(s, robot.t + 0.2, robot.t + 30.0, offset=jump)
                         for s in (SensorId.SFR, SensorId.SFL)]
    run(ctrl, robot, until=lambda c: c.phase is not Phase.DESCENT_DRIVE_SECOND)
    return at - robot.front_x, events


def test_a_drive_whose_reading_jumps_goes_on_by_turns_not_by_the_new_reading() -> None:
    clean, _ = _descent_3_travel(0.0)
    jumped, events = _descent_3_travel(0.08)
    assert jumped == pytest.approx(clean, abs=0.005)  # not cut short by 8 cm
    assert any("jumped" in e.message for e in of(events, EventKind.INFO))


def test_a_burst_at_the_end_of_the_wait_does_not_decide_it() -> None:
    """Found by the envelope sweep (cases 596 and 1359 on sonar): two stray
    HC-SR04 measurements passed SFR's median in the wait's last 0.2 s, and
    the smoothed difference they filled ended a sound run with "still
    disagree".  The median of the wait's ticks decides."""
    ctrl, robot, events = start(faults=[Fault(SensorId.SFL, 7.0, 9.0, offset=0.05)])
    run(ctrl, robot, until=lambda c: c.phase is Phase.PAUSED)
    end = robot.t + WAIT
    robot.faults.append(Fault(SensorId.SFL, end - 0.3, end, offset=0.3))
    run(ctrl, robot)
    r = ctrl.result
    assert (r.outcome, r.pauses, r.steps_climbed, r.steps_descended) == ("completed", 1, 2, 2)
    assert len(of(events, EventKind.RESUME)) == 1


def test_a_pair_that_reads_nothing_when_the_wait_ends_does_not_disagree() -> None:
    """Found by the envelope sweep (case 474 and four more on ir): near the
    top the Sharp beams read the landing beyond, grazing, and disagreed for
    most of the wait; when it ended they read nothing at all.  A median over
    the whole wait still said "disagree" and ended a sound run; the pair
    gives no difference at the decision, so it does not disagree (and the
    median is over the wait's last second)."""
    ctrl, robot, _events = start(faults=[Fault(SensorId.SFL, 7.0, 9.0, offset=0.05)])
    run(ctrl, robot, until=lambda c: c.phase is Phase.PAUSED)
    end = robot.t + WAIT
    robot.faults += [Fault(SensorId.SFL, 9.0, end - 0.1, offset=0.05),
                     Fault(SensorId.SFL, end - 0.1, end + 0.1, offset=2.0),
                     Fault(SensorId.SFR, end - 0.1, end + 0.1, offset=2.0)]
    run(ctrl, robot)
    r = ctrl.result
    assert (r.outcome, r.steps_climbed, r.steps_descended) == ("completed", 2, 2), r.error


def test_a_sensor_stale_while_the_link_lost_frames_names_the_link() -> None:
    """A robot on a lossy wire: its readings go stale because the replies
    are lost, and the error says what the link counted meanwhile."""
    ctrl, robot, _ = start(faults=[Fault(SensorId.SFL, 25.0, freeze=True)])
    read = robot.read
    figures = {"retries": 0.0, "timeouts": 0.0, "lost": 0.0}

    def lossy() -> Snapshot:
        snap = read()
        if snap.time_s > 25.0:
            figures["retries"] += 3
            figures["timeouts"] += 1
        return replace(snap, health=dict(figures))

    robot.read = lossy  # type: ignore[method-assign]
    run(ctrl, robot)
    error = str(ctrl.result.error)
    assert "SFL stale" in error and "meanwhile the link lost frames (" in error
    assert " retries, " in error and " timeouts)" in error and "lost)" not in error


def test_a_sensor_stale_on_a_link_that_lost_nothing_says_nothing_of_it() -> None:
    ctrl, robot, _ = start(faults=[Fault(SensorId.SFL, 25.0, freeze=True)])
    read = robot.read
    robot.read = lambda: replace(read(), health={"retries": 7.0})  # type: ignore[method-assign]
    run(ctrl, robot)
    assert "SFL stale" in str(ctrl.result.error) and "link" not in str(ctrl.result.error)
