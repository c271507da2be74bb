"""The VL53L5CX preset: a block of zones as a rectangle of rays, on the grid
the config checks hold it to, and what one row of zones reads of a low riser
behind a long tread (worked out here in closed form, one ray at a time, not
by the beams' casts)."""

from __future__ import annotations

import math

import pytest

from stairbot.control.robot_config import parse_config
from stairbot.errors import ConfigError
from stairbot.fakes.sensor_model import Cause, SensorModel, combine
from stairbot.fakes.sensor_presets import VL53L5CX, front_blocks, model_for
from stairbot.inputs.sensor_specs import ROW_SWITCH_PITCH_DEG, SPECS, rows_up

ROW_ABOVE_AXIS = """extends = "reference"
[sensors]
front_model = "vl53l5cx"
front_fov_deg = 5.625
front_tilt_deg = 2.8125
"""


def zone_row() -> SensorModel:
    return model_for(parse_config(ROW_ABOVE_AXIS, "zone.toml").sensors, back=False)


def test_the_spec_is_an_8x8_grid_of_5625_degree_zones_at_15_hz() -> None:
    spec = SPECS["vl53l5cx"]
    assert (spec.fov_deg, spec.zones, spec.zone_deg) == (45.0, 8, 5.625)
    assert spec.period_s == pytest.approx(1 / 15) and spec.latency_s == pytest.approx(1 / 15)
    assert (VL53L5CX.fov_deg, VL53L5CX.fov_across_deg) == (45.0, 11.25)  # two columns


def test_one_row_is_a_rectangle_of_rays_two_per_zone_all_weighted_alike() -> None:
    m = zone_row()
    assert (m.fov_deg, m.fov_across_deg, m.tilt_deg) == (5.625, 11.25, 2.8125)
    ups = sorted({round(math.degrees(up), 6) for up, _, _ in m.cone})
    acrosses = sorted({round(math.degrees(a), 6) for _, a, _ in m.cone})
    assert ups == [-2.8125, 0.0, 2.8125]  # about the axis: level, 2.8125 and 5.625 up
    assert acrosses == [-5.625, -2.8125, 0.0, 2.8125, 5.625]
    assert len(m.cone) == 15 and {w for _, _, w in m.cone} == {1.0}
    two_rows = model_for(parse_config(ROW_ABOVE_AXIS.replace("5.625\n", "11.25\n").replace(
        "2.8125", "5.625"), "zone.toml").sensors, back=False)
    assert two_rows.rays == 5 and len(two_rows.cone) == 25


def test_a_round_cone_is_unchanged() -> None:
    cone = SensorModel(name="c", fov_deg=15.0, rays=5, rays_across=3)
    assert len(cone.cone) < 15 and max(w for _, _, w in cone.cone) == 1.0
    assert min(w for _, _, w in cone.cone) == pytest.approx(0.5, abs=0.1)


def side_view_reading(model: SensorModel, h: float, tread: float, rise: float) -> float:
    """The row's reading, from ``h`` above a tread ``tread`` long (the riser
    ahead ``tread`` + 0.01 m away, ``rise`` high, then steps of the comfort
    rule): each ray's first riser in closed form, slanted by its angle
    across, mixed by :func:`combine`."""
    d0 = tread + 0.01
    beyond = max(0.22, 0.62 - 2 * rise)
    hits = []
    for up, across, weight in model.cone:
        theta = math.radians(model.tilt_deg) + up
        assert theta >= -1e-12  # no ray looks down: nothing meets the tread
        for i in range(12):  # riser i stands d0 + i * beyond ahead, from i * rise up
            x = d0 + i * beyond
            if h + x * math.tan(theta) <= (i + 1) * rise:
                length = x / math.cos(theta) / math.cos(across)
                hits.append((length, math.cos(theta) * math.cos(across), weight))
                break
    d, cause = combine(model, hits, sum(w for _, _, w in model.cone))
    assert cause is Cause.OK and d is not None
    return d - d0


def test_one_row_reads_a_0090_riser_behind_a_040_tread_and_not_a_0075_one() -> None:
    # h = 0.038 m: the sensor at the end of ascent 3's lift, where min_rise_for
    # puts the top ray; the rule asks for 0.088 m there
    m = zone_row()
    alone = side_view_reading(m, 0.038, 0.40, 0.5)  # a riser taller than any ray reaches
    assert abs(alone) < 0.005  # the rays across slant a little
    assert side_view_reading(m, 0.038, 0.40, 0.090) == pytest.approx(alone, abs=0.005)
    assert side_view_reading(m, 0.038, 0.40, 0.075) > alone + 0.005  # the top rays pass over
    rule = parse_config(ROW_ABOVE_AXIS, "zone.toml").min_rise_for(0.40)
    assert rule == pytest.approx(0.088, abs=0.0005)


@pytest.mark.parametrize(
    ("sensors", "field", "words"),
    [
        ("front_fov_deg = 5.0", "sensors.front_fov_deg",
         "5 degrees is not a whole number of the vl53l5cx's 5.625-degree rows of zones; "
         "allowed: 5.625, 11.25"),
        ("front_fov_deg = 5.625\nfront_tilt_deg = 2.0", "sensors.front_tilt_deg",
         "off the vl53l5cx's grid"),
        ("front_fov_deg = 5.625\nfront_tilt_deg = -2.8125", "sensors.front_tilt_deg",
         "lowest rays look 5.625 degrees down and meet the floor 0.305 m ahead"),
        ("front_fov_deg = 5.625\nfront_tilt_deg = 22.5", "sensors.front_tilt_deg",
         "off the vl53l5cx's grid"),
        ("front_fov_deg = 45.0\nfront_tilt_deg = 0.0", "sensors.front_tilt_deg",
         "meet the floor 0.072 m ahead"),
    ],
)
def test_a_block_off_the_grid_or_looking_at_the_floor_is_refused(
        sensors: str, field: str, words: str) -> None:
    text = f'extends = "reference"\n[sensors]\nfront_model = "vl53l5cx"\n{sensors}\n'
    with pytest.raises(ConfigError) as info:
        parse_config(text, "robot.toml")
    assert info.value.field == field
    assert words in str(info.value)


@pytest.mark.parametrize("pair", ["back_model", "side_model"])
def test_a_multizone_sensor_is_a_front_pair_only(pair: str) -> None:
    text = f'extends = "landings"\n[sensors]\n{pair} = "vl53l5cx"\n'
    with pytest.raises(ConfigError, match="modelled on the front pair only") as info:
        parse_config(text, "robot.toml")
    assert info.value.field == f"sensors.{pair}"


def test_the_rows_above_the_axis_are_accepted() -> None:
    for rows in range(1, 5):  # a block from level up, 1 to 4 rows tall
        fov = rows * 5.625
        text = (f'extends = "reference"\n[sensors]\nfront_model = "vl53l5cx"\n'
                f"front_fov_deg = {fov}\nfront_tilt_deg = {fov / 2}\n")
        cfg = parse_config(text, "robot.toml")
        assert cfg.front_cone_top_rad == pytest.approx(math.radians(fov))


def test_pitched_nose_down_the_board_moves_the_row_up_so_no_ray_looks_at_the_floor() -> None:
    assert [rows_up(p, 5.625) for p in (3.0, 0.0, -ROW_SWITCH_PITCH_DEG, -2.1, -6.2,
                                         -7.625, -7.7)] == [0, 0, 0, 1, 1, 1, 2]
    blocks = front_blocks(parse_config(ROW_ABOVE_AXIS, "zone.toml").sensors)
    assert [b.tilt_deg for b in blocks] == [2.8125 + k * 5.625 for k in range(4)]  # to 22.5
    assert {b.cone for b in blocks} == {blocks[0].cone}  # the same rays, turned up
    for pitch in (-2.1, -4.9, -6.2, -9.0):  # the block's lowest ray, in the world
        block = blocks[rows_up(pitch, 5.625)]
        lowest = pitch + block.tilt_deg - block.fov_deg / 2
        assert -ROW_SWITCH_PITCH_DEG <= lowest < 5.625
    vl53l1x = 'extends = "reference"\n[sensors]\nfront_model = "vl53l1x"\nfront_fov_deg = 15.0\n'
    assert len(front_blocks(parse_config(vl53l1x, "cone.toml").sensors)) == 1
