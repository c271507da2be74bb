"""The distance sensor model, the top-view geometry and the stairs' ray casts."""

from __future__ import annotations

import math
import random

import pytest

from stairbot.fakes.plan import Plan
from stairbot.fakes.sensor_model import Cause, ModelSensor, SensorModel
from stairbot.fakes.sensor_presets import IDEAL
from stairbot.fakes.stairs import StairsProfile
from stairbot.hardware import SensorId, SensorStatus
from stairbot.inputs.scenario import Fault


def sensor(noise: float = 0.0, seed: int = 1, faults: tuple[Fault, ...] = (),
           sid: SensorId = SensorId.SFL) -> ModelSensor:
    return ModelSensor(sid, IDEAL, 0.03, 1.3, 0.001, noise, seed, faults)


def test_readings_are_rounded_to_the_resolution() -> None:
    r = sensor().measure(0.43261, 0.0)
    assert r.status is SensorStatus.OK
    assert r.distance_m == 0.433


def test_nothing_or_too_far_is_out_of_range_at_the_maximum() -> None:
    s = sensor()
    for far in (None, 1.31, 50.0):
        r = s.measure(far, 0.0)
        assert (r.status, r.distance_m) == (SensorStatus.OUT_OF_RANGE, 1.3)
    assert s.measure(1.3, 0.0).status is SensorStatus.OK


def test_too_near_is_out_of_range_at_the_minimum() -> None:
    r = sensor().measure(0.01, 0.0)
    assert (r.status, r.distance_m) == (SensorStatus.OUT_OF_RANGE, 0.03)


def test_noise_is_gaussian_with_the_scenario_sigma_and_seeded() -> None:
    a = [sensor(0.005, seed=7).measure(0.5, 0.0).distance_m for _ in range(1)]
    s1, s2 = sensor(0.005, seed=7), sensor(0.005, seed=7)
    seq1 = [s1.measure(0.5, 0.0).distance_m for _ in range(2000)]
    seq2 = [s2.measure(0.5, 0.0).distance_m for _ in range(2000)]
    assert seq1 == seq2 and seq1[0] == a[0]
    mean = sum(seq1) / len(seq1)
    sd = math.sqrt(sum((v - mean) ** 2 for v in seq1) / len(seq1))
    assert mean == pytest.approx(0.5, abs=0.0005)
    assert sd == pytest.approx(0.005, rel=0.1)
    other_seed = [sensor(0.005, seed=8).measure(0.5, 0.0).distance_m for _ in range(20)]
    other_sensor = [sensor(0.005, seed=7, sid=SensorId.SFR).measure(0.5, 0.0).distance_m
                    for _ in range(20)]
    assert other_seed != seq1[:20] and other_sensor != seq1[:20]


def test_offset_fault_applies_only_in_its_window() -> None:
    s = sensor(faults=(Fault(at=2.0, sensor="SFL", kind="offset", offset=0.05, duration=1.0),))
    assert s.measure(0.4, 1.99).distance_m == 0.4
    assert s.measure(0.4, 2.0).distance_m == 0.45
    assert s.measure(0.4, 2.99).distance_m == 0.45
    assert s.measure(0.4, 3.0).distance_m == 0.4


def test_error_fault_without_duration_lasts_to_the_end() -> None:
    s = sensor(faults=(Fault(at=1.0, sensor="SFL", kind="error"),))
    assert s.measure(0.4, 0.5).status is SensorStatus.OK
    for t in (1.0, 10.0, 1000.0):
        assert s.measure(0.4, t).status is SensorStatus.ERROR


def test_a_stuck_sensor_repeats_its_last_measurement_fresh_then_reads_on() -> None:
    fault = Fault(at=1.0, sensor="SFL", kind="stuck", duration=1.0)
    s, healthy = sensor(0.002, seed=3, faults=(fault,)), sensor(0.002, seed=3)
    got, want = [], []
    for i in range(300):  # every 10 ms the truth comes 1 mm nearer
        t, truth = round(i * 0.01, 9), 0.6 - i * 0.001
        s.measure(truth, t)
        got.append((t, s.published(t)))
        want.append(healthy.measure(truth, t))
    before = [r for t, r in got if t < 1.0]
    during = [r for t, r in got if 1.0 <= t < 2.0]
    after = [r for t, r in got if t >= 2.0]
    assert before == want[:100] and len(set(before)) > 50  # noisy, and moving
    assert {r for r in during} == {before[-1]}  # the last one before, as it was
    assert all(r.ok and r.age_s == 0.0 for r in during)  # fresh: measured at every read
    assert after == want[200:]  # the same draws were made: the same readings after


def test_a_slow_stuck_sensor_publishes_on_time_fresh_and_constant() -> None:
    model = SensorModel(name="slow", period_s=0.05, latency_s=0.02)
    s = ModelSensor(SensorId.SFR, model, 0.03, 1.3, 0.001, 0.0, 1,
                    (Fault(at=0.5, sensor="SFR", kind="stuck"),))
    seen = []
    for i in range(200):  # reads every 10 ms; the truth moves 1 mm per read
        t = round(i * 0.01, 9)
        s.measure(0.8 - i * 0.001, t)
        seen.append((t, s.published(t)))
    assert s.measurements == 40  # one every 50 ms, fault or not
    stuck = [r for t, r in seen if t >= 0.52]  # measured from 0.5 on, published 20 ms later
    assert {r.distance_m for r in stuck} == {0.755}  # measured at 0.45: 0.8 - 0.045
    assert max(r.age_s for r in stuck) <= 0.05 + 0.02 + 1e-9  # never older than fresh
    assert s.cause is Cause.FAULT


def test_a_sensor_stuck_from_the_start_repeats_its_first_measurement() -> None:
    s = sensor(faults=(Fault(at=0.0, sensor="SFL", kind="stuck"),))
    assert [s.measure(0.5 - i * 0.01, i * 0.02).distance_m for i in range(5)] == [0.5] * 5


def test_faults_of_other_sensors_do_not_apply() -> None:
    s = sensor(faults=(Fault(at=0.0, sensor="SFR", kind="error"),))
    assert s.measure(0.4, 5.0).status is SensorStatus.OK


# -- top view ---------------------------------------------------------------------
def test_square_to_the_riser_the_beam_reads_the_side_view_distance() -> None:
    plan = Plan(width=1.0, side_wall="none")
    assert plan.front_distance(0.1, 0.05, 0.4, 1.0) == pytest.approx(0.4)
    assert plan.front_distance(0.1, 0.05, None, 1.0) is None


def test_turned_left_the_left_sensor_reads_further() -> None:
    yaw = math.radians(5.0)
    plan = Plan(width=1.0, side_wall="none", yaw=yaw)
    fwd, lat, dx = 0.1125, 0.05, 0.4
    left = plan.front_distance(fwd, lat, dx, 1.0)
    right = plan.front_distance(fwd, -lat, dx, 1.0)
    assert left is not None and right is not None
    assert left > right
    assert left - right == pytest.approx(2 * lat * math.tan(yaw), rel=1e-9)
    expected_left = (dx + fwd * (1 - math.cos(yaw)) + lat * math.sin(yaw)) / math.cos(yaw)
    assert left == pytest.approx(expected_left)


def test_a_beam_leaving_the_flight_meets_the_side_wall_or_nothing() -> None:
    yaw = math.radians(30.0)
    walled = Plan(width=0.6, side_wall="left", y=0.1, yaw=yaw)
    open_side = Plan(width=0.6, side_wall="right", y=0.1, yaw=yaw)
    fwd, lat, dx = 0.1125, 0.05, 0.8  # the riser is far: the beam crosses y = 0.3 first
    d = walled.front_distance(fwd, lat, dx, 1.0)
    y_mount = 0.1 + fwd * math.sin(yaw) + lat * math.cos(yaw)
    assert d == pytest.approx((0.3 - y_mount) / math.sin(yaw))
    assert open_side.front_distance(fwd, lat, dx, 1.0) is None


def test_corner_each_sensor_sees_a_different_wall() -> None:
    # near the left wall, turned towards it: SFL meets the wall, SFR the riser
    yaw = math.radians(20.0)
    plan = Plan(width=0.5, side_wall="left", y=0.15, yaw=yaw)
    fwd, lat, dx = 0.1125, 0.05, 0.3
    sfl = plan.front_distance(fwd, lat, dx, 1.0)
    sfr = plan.front_distance(fwd, -lat, dx, 1.0)
    assert sfl is not None and sfr is not None
    y_sfl = 0.15 + fwd * math.sin(yaw) + lat * math.cos(yaw)
    assert sfl == pytest.approx((0.25 - y_sfl) / math.sin(yaw))
    dx_sfr = dx + fwd * (1 - math.cos(yaw)) - lat * math.sin(yaw)
    assert sfr == pytest.approx(dx_sfr / math.cos(yaw))


def test_the_yaws_trigonometry_follows_the_yaw() -> None:
    plan = Plan(width=1.0, side_wall="none", yaw=0.1)
    angles = (-0.05, 0.0, 0.05)
    for yaw in (0.1, 0.1, -0.2, 0.0, -0.0, 0.3, 0.3):
        plan.yaw = yaw
        c, s = plan.yaw_trig()
        assert (c, math.copysign(1.0, s), s) == (math.cos(yaw), math.copysign(1.0, math.sin(yaw)),
                                                  math.sin(yaw))
        assert plan.turned(angles) == [(math.cos(yaw + a), math.sin(yaw + a)) for a in angles]
        assert plan.turned((0.1,)) == [(math.cos(yaw + 0.1), math.sin(yaw + 0.1))]


def test_moving_on_a_heading_changes_the_lateral_position() -> None:
    plan = Plan(width=1.0, side_wall="none", yaw=math.radians(10.0))
    plan.move(0.2)
    assert plan.y == pytest.approx(0.2 * math.tan(math.radians(10.0)))


# -- stairs profile -------------------------------------------------------------------
STEPS = [(-1.0, 0.0), (0.0, 0.0), (0.0, 0.17), (0.28, 0.17), (0.28, 0.34), (3.0, 0.34)]


def test_horizontal_ray_hits_the_riser_surface() -> None:
    prof = StairsProfile(STEPS, radius=0.001)
    assert prof.ray(-0.5, 0.05, 1.0, 0.05) == pytest.approx((-0.001, 0.05))
    assert prof.ray(-0.5, 0.2, 1.0, 0.2) == pytest.approx((0.279, 0.2))
    assert prof.ray(-0.5, 0.5, 1.0, 0.5) is None
    assert prof.ray(-0.5, 0.05, -0.2, 0.05) is None  # too short to reach


def test_downward_ray_hits_the_tread_surface() -> None:
    prof = StairsProfile(STEPS, radius=0.001)
    assert prof.ray(0.1, 0.3, 0.1, -1.0) == pytest.approx((0.1, 0.171))
    assert prof.ray(-0.1, 0.3, -0.1, -1.0) == pytest.approx((-0.1, 0.001))


def _crossing(seg: tuple[float, float, float, float], x0: float, y0: float, x1: float,
              y1: float) -> float:
    """Where the segment (x0, y0)-(x1, y1) crosses ``seg`` (its parameter), or inf:
    plain line-segment intersection, written apart from StairsProfile's."""
    ax, ay, bx, by = seg
    rx, ry, sx, sy = x1 - x0, y1 - y0, bx - ax, by - ay
    denom = rx * sy - ry * sx
    if denom == 0.0:
        return math.inf
    t = ((ax - x0) * sy - (ay - y0) * sx) / denom
    u = ((ax - x0) * ry - (ay - y0) * rx) / denom
    return t if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0 else math.inf


def test_profile_agrees_with_brute_force_on_random_rays() -> None:
    prof = StairsProfile(STEPS, radius=0.0)
    rng = random.Random(3)
    for _ in range(2000):
        x0, y0 = rng.uniform(-0.8, 2.5), rng.uniform(0.35, 1.0)  # above everything
        a = rng.uniform(-math.pi, 0.0)
        x1, y1 = x0 + 1.5 * math.cos(a), y0 + 1.5 * math.sin(a)
        best = math.inf
        for seg in prof.segments:
            best = min(best, _crossing(seg, x0, y0, x1, y1))
        got = prof.ray(x0, y0, x1, y1)
        if best == math.inf:
            assert got is None
        else:
            assert got == pytest.approx((x0 + (x1 - x0) * best, y0 + (y1 - y0) * best))


def test_a_models_cone_tables_are_made_once_with_the_model_and_follow_a_replace() -> None:
    """What the casts read every tick is made when the model is, not at each
    read (a compiled build runs a cached_property's body at every read), and
    a model replaced with other fields gets its own."""
    from dataclasses import replace
    cone = SensorModel(name="c", fov_deg=15.0, rays=5, rays_across=3, tilt_deg=2.0,
                       max_incidence_deg=60.0)
    for name in ("cone", "fan", "cone_rows"):
        assert getattr(cone, name) is getattr(cone, name), name
    assert cone.cone_index[2] is cone.cone_index[2]  # (compiled, the triple is boxed anew)
    assert len(cone.fan) == 5 and len(cone.cone) > len(cone.fan)
    assert cone.tilt == pytest.approx(math.radians(2.0))
    assert cone.min_cos == pytest.approx(0.5)
    narrow = replace(cone, rays=3, max_incidence_deg=None)
    assert len(narrow.fan) == 3 and narrow.min_cos == 1.0
    assert narrow != cone and replace(cone) == cone and hash(replace(cone)) == hash(cone)
