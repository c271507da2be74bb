"""The robot config: seed names, derived turn counts, and errors that name the
file, the field and what is allowed."""

from __future__ import annotations

import math
import re
import tomllib
from importlib import resources
from pathlib import Path

import pytest

from stairbot.control.algorithm import limits
from stairbot.control.robot_config import load_config, parse_config
from stairbot.errors import ConfigError

DEFAULT_TEXT = resources.files("stairbot.inputs").joinpath("default_robot.toml").read_text("utf-8")


def with_change(section: str, key: str, value: str | None) -> str:
    """The default config text with one key replaced (value None: removed)."""
    out, current = [], None
    for line in DEFAULT_TEXT.splitlines():
        stripped = line.strip()
        if stripped.startswith("["):
            current = stripped.strip("[]")
        if current == section and stripped.split("=")[0].strip() == key:
            if value is not None:
                out.append(f"{key} = {value}")
            continue
        out.append(line)
    text = "\n".join(out) + "\n"
    assert text != DEFAULT_TEXT + "\n" or value is not None
    return text


def test_default_loads_and_derives_the_reference_robot() -> None:
    cfg = load_config()
    assert cfg.LENGTH_OF_A_ROBOT == pytest.approx(0.225)
    assert cfg.wheel_circumference == pytest.approx(2 * math.pi * 0.016)
    assert cfg.MAX_OF_VERTICAL_TURNS == pytest.approx(105)
    assert cfg.NUMBER_OF_VERTICAL_TURNS_FOR_CLEARANCE == pytest.approx(5)
    assert cfg.initial_number_of_vertical_turns == pytest.approx(19)
    approach = cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH
    assert approach == pytest.approx(0.09 / cfg.wheel_circumference)
    assert cfg.BACK_CLEARANCE == pytest.approx(0.04)


def test_the_reference_robot_climbs_residential_stairs() -> None:
    cfg = load_config()
    assert cfg.max_step_rise_m >= 0.18  # rise 0.15-0.18 m
    assert limits.min_tread_m(cfg) <= 0.26  # tread 0.26-0.30 m


def test_to_dict_has_every_section_and_the_derived_values() -> None:
    d = limits.config_dict(load_config())
    assert set(d) >= {"geometry", "masses", "motors", "sensors", "algorithm", "safety", "derived",
                      "source"}
    assert d["derived"]["max_step_rise_m"] == pytest.approx(0.202)
    assert d["derived"]["min_tread_m"] == pytest.approx(0.26)
    assert d["geometry"]["LENGTH_OF_A_ROBOT"] == 0.225


def test_turn_counts_follow_the_geometry() -> None:
    cfg = parse_config(with_change("geometry", "wheel_radius", "0.018"), "big.toml")
    assert cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE == pytest.approx(
        0.075 / (2 * math.pi * 0.018))


def test_length_of_a_robot_equal_to_the_segments_is_accepted() -> None:
    text = DEFAULT_TEXT.replace("[geometry]\n", "[geometry]\nLENGTH_OF_A_ROBOT = 0.225\n")
    assert parse_config(text, "x.toml").LENGTH_OF_A_ROBOT == pytest.approx(0.225)


@pytest.mark.parametrize(
    ("text", "field", "words"),
    [
        (DEFAULT_TEXT.replace("[geometry]\n", "[geometry]\nLENGTH_OF_A_ROBOT = 0.3\n"),
         "geometry.LENGTH_OF_A_ROBOT", "add up to"),
        (with_change("geometry", "wheel_radius", "-0.016"), "geometry.wheel_radius",
         ">= 0.001 and <= 10"),
        (with_change("motors", "lift_speed", '"fast"'), "motors.lift_speed", "a number"),
        (with_change("masses", "wheel", None), "masses.wheel", "required"),
        (DEFAULT_TEXT.replace("[masses]\n", "[masses]\nbattery = 1.0\n"), "masses.battery",
         "allowed keys here: first_module"),
        (DEFAULT_TEXT + "\n[extra]\nx = 1\n", "extra", "allowed keys here: geometry"),
        (with_change("algorithm", "max_steps", "25"), "algorithm.max_steps", "<= 20"),
        (with_change("algorithm", "LENGTH_OF_INFINITY", "2.0"), "algorithm.LENGTH_OF_INFINITY",
         "front_max_range"),
        (with_change("sensors", "front_min_range", "1.5"), "sensors.front_min_range", "below"),
        (with_change("safety", "max_pitch_deg", "40.0"), "safety.max_pitch_deg",
         "40.0 is not allowed; allowed: a number > 0 and <= 30"),
        (with_change("safety", "max_rate_dps", "0"), "safety.max_rate_dps", "> 0 and <= 1000"),
        (with_change("safety", "imu", '"yes"'), "safety.imu", "allowed: true or false"),
        (with_change("safety", "imu_max_age_s", None), "safety.imu_max_age_s", "required"),
        (with_change("safety", "stability_margin", "0.02"), "safety.stability_margin",
         "allowed: 0 <= stability_margin < LENGTH_OF_SECOND_MODULE / 2 - wheel_inset = 0.0190 m"),
        (DEFAULT_TEXT[:DEFAULT_TEXT.index("[safety]")], "safety", "required but missing"),
        (with_change("sensors", "front_model", '"lidar"'),
         "sensors.front_model",
         "'lidar' is not allowed; allowed: one of 'gp2y0a21', 'hcsr04', 'ideal', 'vl53l0x', "
         "'vl53l1x'"),
        (with_change("sensors", "back_model", '"gp2y0a21"'),
         "sensors.back_height", "read from 0.1 m: the floor would be out of range"),
        (with_change("sensors", "front_model", '"gp2y0a21"'),
         "algorithm.LENGTH_OF_INFINITY", "(gp2y0a21) read at most 0.8 m"),
        (with_change("sensors", "front_fov_deg", "50"),
         "sensors.front_fov_deg", "wider than the vl53l5cx's 45.0-degree cone"),
        (with_change("sensors", "front_fov_deg", "40"),
         "sensors.front_fov_deg", "40 degrees is not a whole number of the vl53l5cx's "
         "5.625-degree rows of zones; allowed: 5.625, 11.25"),
        (with_change("sensors", "front_fov_deg", "-1.0"),
         "sensors.front_fov_deg", "-1.0 is not allowed; allowed: a number >= 0 and <= 90"),
        (with_change("sensors", "front_model", '"ideal"'),  # the row of zones left on one ray
         "sensors.front_fov_deg",
         "5.625 degrees, but the ideal model is one ray; allowed: 0, one ray along the mount"),
        (with_change("sensors", "front_tilt_deg", "60"),
         "sensors.front_tilt_deg", "<= 45"),
    ],
)
def test_bad_configs_name_the_file_the_field_and_what_is_allowed(
        text: str, field: str, words: str) -> None:
    with pytest.raises(ConfigError) as info:
        parse_config(text, "robot.toml")
    err = info.value
    assert err.source == "robot.toml"
    assert err.field == field
    assert words in str(err)
    assert str(err).startswith(f"robot.toml: {field}: ")
    assert "\n" not in str(err)


def test_not_toml_is_a_config_error() -> None:
    with pytest.raises(ConfigError, match="not valid TOML"):
        parse_config("[geometry\nx = ", "broken.toml")


def test_missing_file_is_a_config_error(tmp_path: Path) -> None:
    missing = tmp_path / "nope.toml"
    with pytest.raises(ConfigError, match="cannot read") as info:
        load_config(missing)
    assert info.value.source == str(missing)


def test_the_default_file_is_valid_toml_with_seed_names() -> None:
    raw = tomllib.loads(DEFAULT_TEXT)
    assert "SAFE_DISTANCE_IN_FRONT_OF_STEP" in raw["algorithm"]
    assert "LENGTH_OF_FIRST_MODULE" in raw["geometry"]


def test_a_shipped_robot_by_name_and_a_config_that_extends_another(tmp_path: Path) -> None:
    reference = load_config("reference")
    assert (reference.sensors.front_model, reference.sensors.back_model) == ("vl53l5cx", "vl53l0x")
    assert (reference.sensors.front_fov_deg, reference.sensors.front_tilt_deg) == (5.625, 2.8125)
    assert reference.sensors == load_config().sensors
    ideal = load_config("ideal")
    assert (ideal.sensors.front_model, ideal.sensors.back_model) == ("ideal", "ideal")
    assert ideal.front_cone_top_rad == 0.0  # one level ray: the row's cone and tilt taken back
    assert ideal.geometry == load_config().geometry  # the rest is the reference robot's
    mine = tmp_path / "mine.toml"
    mine.write_text('extends = "reference"\n[sensors]\nfront_tilt_deg = 8.4375\n')
    cfg = load_config(mine)
    assert (cfg.sensors.front_model, cfg.sensors.front_tilt_deg) == ("vl53l5cx", 8.4375)
    beside = tmp_path / "beside.toml"
    beside.write_text('extends = "mine.toml"\n[algorithm]\nmax_steps = 3\n')
    cfg = load_config(beside)
    assert (cfg.sensors.front_tilt_deg, cfg.algorithm.max_steps) == (8.4375, 3)


@pytest.mark.parametrize(("text", "words"), [
    ('extends = "lidar-bot"\n', "no such file, nor a shipped robot; shipped: "
     "heavy_middle, ideal, ir, landings, reference, sonar"),
    ("extends = 3\n", "must be a shipped robot's name "
     "(heavy_middle, ideal, ir, landings, reference, sonar)"),
    ('extends = "loop.toml"\n', "makes a loop"),
])
def test_bad_extends_is_one_clear_error(tmp_path: Path, text: str, words: str) -> None:
    path = tmp_path / "loop.toml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=re.escape(words)):
        load_config(path)
