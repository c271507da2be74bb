"""The realistic sensor models: presets, timing, outliers and dropouts, cones."""

from __future__ import annotations

import math
import random
from dataclasses import replace
from typing import get_args

import msgspec
import pytest
from reference_sensor import RangeSensor

from stairbot.control.robot_config import load_config
from stairbot.fakes.beams import front_hits, total_weight
from stairbot.fakes.plan import Plan
from stairbot.fakes.sensor_model import Cause, ModelSensor, SensorModel, combine
from stairbot.fakes.sensor_presets import HCSR04, IDEAL, PRESETS, VL53L0X, preset
from stairbot.fakes.sim import SimRobot
from stairbot.hardware import SensorId, SensorStatus
from stairbot.inputs.scenario import Fault, load_scenario
from stairbot.inputs.sections import SensorModelName

SFL = SensorId.SFL


def model_sensor(model: SensorModel, noise: float = 0.0, seed: int = 1,
                 faults: tuple[Fault, ...] = ()) -> ModelSensor:
    return ModelSensor(SFL, model, 0.03, 1.3, 0.001, noise, seed, faults)


def test_the_presets_are_the_names_the_config_allows() -> None:
    assert set(PRESETS) == set(get_args(SensorModelName))
    reference, ideal = load_config().sensors, load_config("ideal").sensors
    assert (reference.front_model, reference.back_model) == ("vl53l5cx", "vl53l0x")
    assert (ideal.front_model, ideal.back_model) == ("ideal", "ideal")
    with pytest.raises(KeyError, match="allowed: ideal, vl53l1x"):
        preset("lidar")


def test_ideal_reads_bit_for_bit_as_the_range_sensor() -> None:
    faults = (Fault(at=1.0, sensor="SFL", kind="offset", offset=0.03, duration=2.0),
              Fault(at=4.0, sensor="SFL", kind="error", duration=0.5))
    old = RangeSensor(SFL, 0.03, 1.3, 0.001, 0.005, 7, faults)
    new = model_sensor(IDEAL, noise=0.005, seed=7, faults=faults)
    rng = random.Random(5)
    for i in range(5000):
        t = i * 0.001
        truth = None if rng.random() < 0.1 else rng.uniform(0.0, 1.5)
        assert new.measure(truth, t) == old.measure(truth, t)


def test_a_reading_is_held_between_updates_and_published_after_its_latency() -> None:
    model = SensorModel(name="slow", period_s=0.05, latency_s=0.02)
    s = model_sensor(model)
    got = {}
    for i in range(13):  # reads every 10 ms; the truth moves 1 cm per read
        t = round(i * 0.01, 9)
        got[t] = s.measure(0.5 + i * 0.01, t).distance_m
    assert got[0.0] == got[0.01] == got[0.06] == 0.5  # the first is published at once
    assert got[0.07] == got[0.11] == 0.55  # measured at 0.05, published at 0.07
    assert got[0.12] == 0.60  # measured at 0.10
    assert s.age(0.12) == pytest.approx(0.02)
    assert s.measurements == 3


def test_outliers_and_dropouts_come_at_their_rates_and_draws_are_fixed() -> None:
    model = SensorModel(name="faulty", outlier_rate=0.05, dropout_rate=0.10,
                        noise_a=0.002, noise_b=0.01)
    s, blind = model_sensor(model, seed=3), model_sensor(model, seed=3)
    n = 20000
    causes: dict[Cause | None, int] = {}
    statuses: dict[SensorStatus, int] = {}
    for i in range(n):
        r = s.measure(0.4, i * 0.01)
        blind.measure(None, i * 0.01)
        causes[s.cause] = causes.get(s.cause, 0) + 1
        if s.cause is Cause.DROPOUT:
            statuses[r.status] = statuses.get(r.status, 0) + 1
        if s.cause is Cause.OUTLIER:
            assert r.ok and 0.03 <= r.distance_m <= 1.3
    assert causes[Cause.DROPOUT] / n == pytest.approx(0.10, rel=0.2)
    assert causes[Cause.OUTLIER] / n == pytest.approx(0.05 * 0.9, rel=0.2)  # a dropout wins
    assert statuses[SensorStatus.ERROR] / causes[Cause.DROPOUT] == pytest.approx(0.5, abs=0.1)
    assert statuses[SensorStatus.OUT_OF_RANGE] + statuses[SensorStatus.ERROR] == causes[
        Cause.DROPOUT]
    # the same number of draws per reading whatever it saw: the streams stay in step
    assert s._uniform.__self__.getstate() == blind._uniform.__self__.getstate()  # type: ignore[attr-defined]


def test_noise_grows_with_range() -> None:
    model = SensorModel(name="n", noise_a=0.001, noise_b=0.02, resolution=0.0)
    s = model_sensor(model, seed=2)

    def sd(d: float) -> float:
        v = [s.measure(d, 0.0).distance_m for _ in range(4000)]
        m = sum(v) / len(v)
        return math.sqrt(sum((x - m) ** 2 for x in v) / len(v))

    assert sd(0.1) == pytest.approx(0.003, rel=0.1)
    assert sd(1.0) == pytest.approx(0.021, rel=0.1)


def test_beyond_the_weak_signal_limit_the_target_is_out_of_range() -> None:
    cone = VL53L0X.cone
    w = total_weight(cone)
    square = [(1.1, 1.0, g) for _, _, g in cone]
    assert combine(VL53L0X, square, w) == (pytest.approx(1.1), Cause.OK)
    far = [(1.3, 1.0, g) for _, _, g in cone]
    assert combine(VL53L0X, far, w) == (None, Cause.WEAK)
    half_beam = [(1.0, 1.0, g) for up, _, g in cone if up > 0.0]  # the rest sees nothing
    assert combine(VL53L0X, half_beam, w) == (None, Cause.WEAK)


# -- cones in the simulated world --------------------------------------------------
def robot() -> SimRobot:
    return SimRobot(load_config("ideal"), load_scenario())  # its world; the models are given


def test_the_cone_sees_a_near_edge_that_a_single_ray_misses() -> None:
    r = robot()
    rise = r.scenario.steps[0].rise
    tread = r.scenario.steps[0].tread
    mount = (-0.05, rise + 0.01)  # 5 cm before riser 1, 1 cm above its edge
    cone = SensorModel(name="cone", fov_deg=27.0, rays=7, aggregate="nearest")
    one = SensorModel(name="one")
    ray = front_hits(r.world, r.plan, one, mount, 0.0, 0.0, (0.0,), 1.5)[0]
    assert combine(one, ray, 1.0)[0] == pytest.approx(tread + 0.05, abs=0.01)
    hits = front_hits(r.world, r.plan, cone, mount, 0.0, 0.0, (0.0,), 1.5)[0]
    d, cause = combine(cone, hits, total_weight(cone.cone))
    assert cause is Cause.OK and d is not None and d < 0.08


@pytest.mark.parametrize(("yaw_deg", "heard"), [(0.0, True), (12.0, True), (25.0, False)])
def test_hcsr04_loses_the_echo_beyond_its_incidence_angle(yaw_deg: float, heard: bool) -> None:
    r = robot()
    plan = Plan(width=4.0, side_wall="none", yaw=math.radians(yaw_deg))
    mount = (-0.3, 0.05)  # the beam meets riser 1
    hits = front_hits(r.world, plan, HCSR04, mount, 0.0, 0.0, (0.0,), 4.2)[0]
    assert hits  # every ray meets the riser ...
    s = model_sensor(HCSR04)
    s.measure(None, 0.0)  # the first reading: nothing
    s.sample(combine(HCSR04, hits, total_weight(HCSR04.cone)), 0.06)
    # (the config's 1.3 m, within the sensor's own 4 m, is the far end)
    assert s.reading(0.06).distance_m == 1.3  # not yet: 25 ms of latency
    reading = s.reading(0.085)
    if heard:  # ... and comes back: the nearest ray, square-ish to it
        assert reading.ok and reading.distance_m == pytest.approx(0.3, abs=0.02)
    else:  # ... but a smooth riser turned 25 degrees reflects the ping away
        assert s.cause is Cause.ECHO_LOST
        assert (reading.status, reading.distance_m) == (SensorStatus.OUT_OF_RANGE, 1.3)


def test_a_preset_robot_reads_reproducibly_and_holds_between_updates() -> None:
    cfg = load_config("ideal")
    cfg = replace(cfg, sensors=msgspec.structs.replace(  # the presets' own cones, level
        cfg.sensors, front_model="vl53l1x", back_model="hcsr04", front_fov_deg=None))
    runs = []
    for _ in range(2):
        r = SimRobot(cfg, load_scenario())
        seq = []
        for _ in range(20):
            seq.append(r.read().sensors)
            r.advance(0.02)
        runs.append(seq)
    assert runs[0] == runs[1]
    fronts = [s[SensorId.SFR] for s in runs[0]]
    # 50 ms period, reads every 20 ms: the value is held, and grows older
    assert len({(r.distance_m, r.status) for r in fronts[:3]}) == 1
    assert [r.age_s for r in fronts[:3]] == pytest.approx([0.0, 0.02, 0.04])
    # the next measurement is due at 50 ms, taken at the read at 60 ms and
    # published after its 50 ms latency: read at 120 ms, it is 60 ms old
    assert [r.age_s for r in fronts[3:7]] == pytest.approx([0.06, 0.08, 0.10, 0.06])
    # 3 cm above the floor, the full 27-degree cone sees the floor ahead of the
    # riser 0.5 m away: the signal-weighted mix reads well short of it
    assert runs[0][0][SensorId.SFR].ok
    assert 0.15 < runs[0][0][SensorId.SFR].distance_m < 0.45
