"""Where the front pair meets the tread ahead (stairbot.control.algorithm.sight),
from each shipped robot's sensor geometry and the pitch: the drives onto a
step end at a reading only where the riser is nearer than that."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from stairbot.control.algorithm import sight
from stairbot.control.robot_config import load_config
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.sensor_specs import ROW_SWITCH_PITCH_DEG

IR = load_config("ir")
REFERENCE = load_config("reference")
SONAR = load_config("sonar")
IDEAL = load_config("ideal")
VL53L1X_FRONT = load_config(str(Path(__file__).parents[1] / "robots" / "vl53l1x_front.toml"))


def test_the_ir_spot_pitched_by_ascent_5_meets_the_tread_short_of_a_0_48_m_treads_riser(
        ) -> None:
    """The level 4-degree spot, 30 mm up, at -4.5 degrees (and the margin's
    degree more): its lowest ray 7.5 degrees down meets the tread 0.22 m
    ahead; ascent 6 starts with the riser of a 0.48 m tread 0.415 m away."""
    assert sight.lowest_heard_deg(IR, -4.5) == pytest.approx(-7.5)
    reach = sight.floor_sight_m(IR, -4.5)
    assert reach == pytest.approx((0.03 - 0.0185 * math.sin(math.radians(5.5)))
                                  / math.tan(math.radians(7.5)))
    assert 0.2 < reach < 0.23
    assert not sight.riser_in_sight(IR, 0.415, -4.5)
    assert sight.riser_in_sight(IR, 0.2, -4.5)  # a 0.26 m tread's riser
    assert sight.riser_in_sight(IR, 0.49, -0.3)  # ascent 4: level, segment 1 lifted


def test_the_reference_robots_board_moves_its_row_up_so_it_reads_the_riser_nose_down(
        ) -> None:
    """The VL53L5CX block's lowest ray runs level; past ROW_SWITCH_PITCH_DEG
    nose down the board publishes the row above: no ray meets the tread."""
    assert sight.floor_sight_m(REFERENCE, -4.5) == math.inf
    assert sight.floor_sight_m(REFERENCE, -3.5) == math.inf
    # just short of the switch the level row looks ROW_SWITCH_PITCH_DEG down
    lowest = sight.lowest_heard_deg(REFERENCE, -1.5)
    assert lowest == pytest.approx(-ROW_SWITCH_PITCH_DEG)
    assert sight.floor_sight_m(REFERENCE, -1.5) > 0.8
    assert sight.lowest_heard_deg(REFERENCE, 0.0) == pytest.approx(-sight.PITCH_MARGIN_DEG)


def test_a_sonar_hears_no_level_tread_at_a_graze() -> None:
    """The HC-SR04's lower rays meet a level tread 80 degrees and more off
    its normal, beyond its echo incidence: the first echo is the riser."""
    for pitch in (0.0, -4.5, -9.0):
        assert sight.lowest_heard_deg(SONAR, pitch) is None
        assert sight.floor_sight_m(SONAR, pitch) == math.inf


@pytest.mark.parametrize("cfg", [IDEAL, VL53L1X_FRONT])
def test_a_level_lowest_ray_meets_the_tread_once_the_robot_pitches_nose_down(
        cfg: RobotConfig) -> None:
    """One level ray (ideal), or a 15-degree cone tilted 7.5 degrees up: the
    lowest ray is level, and pitched with it."""
    assert sight.lowest_heard_deg(cfg, -4.5) == pytest.approx(-5.5)
    assert sight.floor_sight_m(cfg, -4.5) == pytest.approx(0.30, abs=0.015)
    assert sight.lowest_heard_deg(cfg, 2.0) is None


def test_without_an_imu_ascent_6_reckons_with_the_pitch_its_lift_leaves() -> None:
    """drive_clearance (8 mm) over the 0.15 m from segment 1 to segment 3."""
    assert sight.expected_pitch_deg(REFERENCE, True) == pytest.approx(
        -math.degrees(math.atan2(0.008, 0.15)))
    assert sight.expected_pitch_deg(REFERENCE, False) == 0.0
