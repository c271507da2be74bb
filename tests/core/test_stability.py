"""The static-stability check before every lift: the centre of mass against
the carrying wheels on hand-computed cases, the phases' declared supports,
and the controller refusing a lift before anything moves."""

from __future__ import annotations

import math
import random
from dataclasses import replace

import msgspec
import pytest
from kinematic import KinematicRobot, run

from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.stability import UNSTABLE_EDGE, balance, worst
from stairbot.control.algorithm.texts.shared import UNSTABLE
from stairbot.control.algorithm.transitions import TRANSITIONS
from stairbot.control.robot_config import load_config
from stairbot.hardware import LIFT_MOTORS, MotorId
from stairbot.inputs.config import RobotConfig

CFG = load_config()
PER_TURN = CFG.motors.lift_travel_per_turn  # 2 mm


def heavier_front(kg: float) -> RobotConfig:
    return replace(CFG, masses=msgspec.structs.replace(CFG.masses, first_module=kg))


# -- by hand --------------------------------------------------------------------------
# The reference robot: segments 75 mm long, axles 18.5 mm in from their ends, so
# segment 2's axles stand at +-19 mm about its centre, segment 1's at +56 and
# +94 mm, segment 3's at -56 and -94 mm.  Each segment weighs its body plus four
# 20 g wheels: 0.63, 1.38 and 0.63 kg, 2.64 kg in all.
def test_the_symmetric_robot_stands_over_segment_2s_centre() -> None:
    b = balance(CFG, (2,), 0.0, 0.0)
    assert (b.centre_x, b.rear_x, b.front_x) == pytest.approx((0.0, -0.019, 0.019))
    assert b.margin == pytest.approx(0.019)


@pytest.mark.parametrize(("carried_by", "rear", "front"), [
    ((2, 3), -0.094, 0.019),  # lifting segment 1 (ascent 3, descent 6)
    ((1, 3), -0.094, 0.094),  # lifting segment 2 (ascent 5, descent 4)
    ((1, 2), -0.019, 0.094),  # lifting segment 3 (ascent 7, descent 2)
])
def test_the_support_spans_the_outermost_carrying_axles(
        carried_by: tuple[int, ...], rear: float, front: float) -> None:
    b = balance(CFG, carried_by, 40.0, -30.0)  # level: the lifts' heights change nothing
    assert (b.centre_x, b.rear_x, b.front_x) == pytest.approx((0.0, rear, front))


def test_a_heavy_front_segment_stands_ahead_of_segment_2s_front_axle() -> None:
    # segment 1: 2.5 + 0.08 = 2.58 kg at +75 mm; segment 3: 0.63 kg at -75 mm
    # centre of mass: 0.075 * (2.58 - 0.63) / (2.58 + 1.38 + 0.63) = +31.86 mm
    b = balance(heavier_front(2.5), (2, 3), 0.0, 0.0)
    assert b.centre_x == pytest.approx(0.075 * 1.95 / 4.59)
    assert b.margin == pytest.approx(0.019 - 0.075 * 1.95 / 4.59)  # -12.9 mm: outside
    assert balance(heavier_front(2.5), (1, 3), 0.0, 0.0).margin > 0.05  # on both ends: fine


def test_a_pitched_robot_counts_the_heights() -> None:
    # pitched 10 deg nose down, segment 3 lowered 0.1 m (descent 2), segments 1 and 2 carrying.
    # Heights: bodies 22.5 mm above their axles; segment 3's at -100 mm.
    # sum(m y) = 0.55*0.0225 + 1.3*0.0225 + 0.55*(-0.0775) + 0.08*(-0.1) = -0.009 kg m
    # and sum(m x) = 0, so the centre is at (0, -0.009 / 2.64); horizontally
    # x cos - y sin with sin(-10 deg) = -0.173648: -0.003409 * 0.173648 = -0.592 mm.
    c, s = math.cos(math.radians(-10.0)), math.sin(math.radians(-10.0))
    b = balance(CFG, (1, 2), 0.0, -0.1 / PER_TURN, pitch_deg=-10.0)
    assert b.centre_x == pytest.approx(-(-0.009 / 2.64) * s, abs=1e-9)
    assert b.centre_x == pytest.approx(-0.000592, abs=1e-6)
    assert b.rear_x == pytest.approx(-0.019 * c)  # segment 2's rear axle
    assert b.front_x == pytest.approx(0.094 * c)  # segment 1's front axle
    assert b.margin == pytest.approx(-0.000592 + 0.019 * c, abs=1e-6)


def test_a_lift_is_as_stable_as_the_worse_of_its_ends() -> None:
    # nose up 20 deg: segment 1 raised 0.2 m sits 68 mm further back than level
    # (0.2 * sin 20 deg), and takes the centre of mass back with it
    cfg = heavier_front(2.5)
    low = balance(cfg, (2, 3), 0.0, 0.0, pitch_deg=20.0)
    high = balance(cfg, (2, 3), 0.2 / PER_TURN, 0.0, pitch_deg=20.0)
    assert high.margin > low.margin
    assert worst(cfg, (2, 3), (0.0, 0.0), (0.2 / PER_TURN, 0.0), 20.0) == low
    assert worst(cfg, (2, 3), (0.2 / PER_TURN, 0.0), (0.0, 0.0), 20.0) == low


def test_no_carrying_segment_is_a_programming_error() -> None:
    with pytest.raises(ValueError, match="carried_by"):
        balance(CFG, (), 0.0, 0.0)


# -- the phases ------------------------------------------------------------------------
LIFT_PHASES = {
    Phase.CAL_LIFT: (2,), Phase.CAL_LOWER: (2,),
    Phase.ASCENT_LIFT_FIRST: (2, 3), Phase.ASCENT_LIFT_FIRST_MORE: (2, 3),
    Phase.ASCENT_LOWER_OBSTACLE: (2, 3), Phase.ASCENT_LIFT_SECOND: (1, 3),
    Phase.ASCENT_LIFT_THIRD: (1, 2), Phase.DESCENT_LOWER_THIRD: (1, 2),
    Phase.DESCENT_LOWER_SECOND: (1, 3), Phase.DESCENT_LOWER_FIRST: (2, 3),
    Phase.DESCENT_REFUSE: (1, 2), Phase.LANDING_SCAN: (1, 2), Phase.LANDING_SCAN_LOWER: (1, 2),
}


def test_every_phase_that_moves_a_lift_names_what_carries_the_robot() -> None:
    for phase in Phase:
        assert phase.record.carried_by == LIFT_PHASES.get(phase, ()), phase
        to_error = TRANSITIONS[phase].get(Phase.ERROR, "")
        assert to_error.startswith(UNSTABLE_EDGE) is (phase in LIFT_PHASES), phase


def test_the_reference_robot_keeps_its_margin_in_every_lift() -> None:
    for carried_by in set(LIFT_PHASES.values()):
        assert balance(CFG, carried_by, 0.0, 0.0).margin >= CFG.safety.stability_margin


def test_a_lift_past_stability_is_refused_before_anything_moves() -> None:
    cfg = heavier_front(2.5)
    ctrl, robot = Controller(cfg), KinematicRobot(cfg, steps=[(0.17, 0.28)])
    sent = run(ctrl, robot)
    assert ctrl.result.outcome == "error"
    error = str(ctrl.result.error)
    assert error.startswith(f"{UNSTABLE}: calibration — lift segments 1 and 3")
    assert "12.9 mm outside" in error and "segment 2: -19.0 to +19.0 mm" in error
    assert all(speeds[m] == 0.0 for speeds in sent for m in LIFT_MOTORS)
    assert robot.counters[MotorId.MTF] == robot.counters[MotorId.MTB] == 0.0


def test_switched_off_the_check_lets_the_lift_go() -> None:
    cfg = heavier_front(2.5)
    ctrl, robot = Controller(cfg, check_stability=False), KinematicRobot(cfg)
    run(ctrl, robot, until=lambda c: c.phase is Phase.CAL_PROBE)
    assert robot.counters[MotorId.MTF] > 0.0  # the kinematic robot does not topple


def test_the_worst_position_of_a_lift_is_the_least_margin_along_it() -> None:
    # any lift, any pitch, any support: worst() finds the least margin of the
    # whole path, a kink where the outermost carrying axle changes included
    rng = random.Random(5)
    cfg = heavier_front(1.2)
    stroke = cfg.MAX_OF_VERTICAL_TURNS
    kinks = 0
    for _ in range(300):
        carried_by = rng.choice([(2,), (2, 3), (1, 3), (1, 2), (1, 2, 3)])
        pitch = rng.uniform(-40.0, 40.0)
        start = (rng.uniform(-stroke, stroke), rng.uniform(-stroke, stroke))
        end = (rng.uniform(-stroke, stroke), rng.uniform(-stroke, stroke))
        along = [balance(cfg, carried_by, start[0] + f * (end[0] - start[0]),
                         start[1] + f * (end[1] - start[1]), pitch).margin
                 for f in (k / 1000 for k in range(1001))]
        found = worst(cfg, carried_by, start, end, pitch).margin
        assert found <= min(along) + 1e-12
        assert found == pytest.approx(min(along), abs=1e-4)
        ends = min(along[0], along[-1])
        kinks += min(along) < ends - 1e-4
    assert kinks > 5  # the kinks are there, and found
