"""Perception: measurements (not ticks) count, a lone bad measurement decides
nothing, a stale sensor is not used, tolerances follow the stated noise."""

from __future__ import annotations

import msgspec
import pytest

from stairbot.control.perception import CONFIRM, Perception
from stairbot.control.robot_config import load_config
from stairbot.control.tolerances import max_age, pair_tolerance, window
from stairbot.hardware import (
    MotorId,
    MotorState,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
)
from stairbot.inputs.config import RobotConfig

CFG = load_config("ideal")  # the algorithm's logic, on the readings it was written for
TICK = CFG.algorithm.tick
OK, OOR, ERR = SensorStatus.OK, SensorStatus.OUT_OF_RANGE, SensorStatus.ERROR
SFR, SBR = SensorId.SFR, SensorId.SBR


def with_models(front: str, back: str) -> RobotConfig:
    sensors = msgspec.structs.replace(CFG.sensors, front_model=front, back_model=back,
                                      front_fov_deg=None, back_height=0.05)
    return RobotConfig(CFG.source, CFG.geometry, CFG.masses, CFG.motors, sensors, CFG.algorithm,
                       CFG.safety)


def snap(t: float, front: SensorReading, back: SensorReading | None = None,
         turns: float = 0.0) -> Snapshot:
    back = back or SensorReading(0.04)
    sensors = {SensorId.SFR: front, SensorId.SFL: front, SensorId.SBR: back, SensorId.SBL: back}
    motors = {m: MotorState(turns) for m in MotorId}
    return Snapshot(t, sensors, motors)


def feed(p: Perception, readings: list[SensorReading]) -> list[SensorReading]:
    return [p.see(snap(i * TICK, r)).sensors[SFR] for i, r in enumerate(readings)]


def test_the_median_ignores_one_outlier() -> None:
    seen = feed(Perception(CFG), [SensorReading(d) for d in (0.30, 0.30, 0.95, 0.30, 0.30)])
    assert all(r.distance_m == pytest.approx(0.30) for r in seen[2:])


def test_a_new_kind_needs_confirm_measurements_in_a_row() -> None:
    bad = [SensorReading(0.0, ERR)] * (CONFIRM - 1) + [SensorReading(1.3, OOR)] * (CONFIRM - 1)
    seen = feed(Perception(CFG), [SensorReading(0.3)] * 3 + bad + [SensorReading(0.3)])
    assert all(r.status is OK for r in seen)
    seen = feed(Perception(CFG), [SensorReading(0.3)] * 3 + [SensorReading(1.3, OOR)] * CONFIRM)
    assert seen[-1].status is OOR and seen[-2].status is OK


def test_lone_ok_strays_among_near_readings_are_not_in_the_median_when_ok_returns() -> None:
    near = SensorReading(0.03, OOR)
    strays = [near] * CONFIRM + [SensorReading(0.77), near, near, SensorReading(0.85), near]
    back = [SensorReading(0.037), SensorReading(0.25), SensorReading(0.049)]
    seen = feed(Perception(CFG), [SensorReading(0.3)] * 3 + strays + back)
    assert seen[-2].status is OOR
    assert seen[-1].status is OK and seen[-1].distance_m == pytest.approx(0.049)


def test_a_repeated_measurement_counts_once() -> None:
    # a 50 ms sensor read every 20 ms: two error measurements shown over five ticks
    cfg = with_models("vl53l1x", "vl53l0x")
    p = Perception(cfg)
    readings = []
    for i in range(30):
        t = i * TICK
        taken = (t // 0.05) * 0.05
        status = ERR if 0.3 <= taken < 0.4 else OK
        readings.append((t, SensorReading(0.3, status, t - taken)))
    seen = [p.see(snap(t, r)).sensors[SFR] for t, r in readings]
    assert all(r.status is OK for r in seen)


def test_a_sensor_that_stops_measuring_is_stale() -> None:
    cfg = with_models("vl53l1x", "vl53l0x")
    p = Perception(cfg)
    limit = max_age(cfg, back=False)
    seen = []
    for i in range(40):
        t = i * TICK
        taken = min(t, 0.2)  # frozen at 0.2 s: the board repeats it, and its age grows
        seen.append((t, p.see(snap(t, SensorReading(0.3, OK, t - taken))).sensors[SFR]))
    for t, r in seen:
        assert (r.status is ERR) == (t - 0.2 > limit)
    assert p.why(SFR) is not None and "stale" in p.why(SFR)


def test_front_readings_are_carried_forward_by_the_odometer_when_taken() -> None:
    # the robot drives 0.1 m/s towards a wall 1 m away; a 60 ms ultrasonic ranger
    # with 25 ms latency: the filtered reading follows the true distance now
    cfg = with_models("hcsr04", "vl53l0x")
    p = Perception(cfg)
    per_turn = cfg.wheel_circumference
    for i in range(60):
        t = i * TICK
        taken = (t // 0.06) * 0.06 - 0.025 if t >= 0.085 else 0.0
        true_then = 1.0 - 0.1 * max(taken, 0.0)
        r = SensorReading(round(true_then, 3), OK, t - max(taken, 0.0))
        seen = p.see(snap(t, r, turns=0.1 * t / per_turn)).sensors[SFR]
    assert seen.distance_m == pytest.approx(1.0 - 0.1 * t, abs=0.002)


def test_tolerances_follow_the_stated_noise_at_the_distance() -> None:
    cfg = with_models("vl53l0x", "vl53l0x")  # sigma 3 mm + 2 % of the distance
    assert pair_tolerance(cfg, 0.8) > pair_tolerance(cfg, 0.1) >= cfg.algorithm.equal_tolerance
    # every pair's median spans five measurements, slow or fast
    assert window(cfg, back=False) == 5 and window(CFG, back=False) == 5
