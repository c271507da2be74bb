"""The shipped reference robot (VL53L5CX front pair, the row of zones just
above the axis; VL53L0X back pair) on the simulated stairs: the default
stairs up and back, the reach its row gives behind long treads, and rises
too low for what it measures refused by design.  Its former front pair's
tests are in tests/test_vl53l1x_front.py.  The envelope sweep's cases cited
"on tof" were run as `--config tof`, the robot with that former pair."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from simrun import run_sim

from stairbot.control.algorithm import limits
from stairbot.control.robot_config import load_config
from stairbot.events import Event
from stairbot.inputs.scenario import load_scenario, parse_scenario
from stairbot.run.runner import RunResult
from stairbot.sweep.spec import SpecError, load_spec, with_config

REFERENCE = load_config("reference")


def run_reference(text: str | None, events: list[Event] | None = None) -> RunResult:
    """The reference robot on ``text``'s stairs (None: the default ones); the run's
    events go to ``events`` if given."""
    scenario = load_scenario() if text is None else parse_scenario(text, "<reference>")
    return run_sim(REFERENCE, scenario, events)


def test_the_default_stairs_up_and_back() -> None:
    r = run_reference(None)
    assert (r.outcome, r.ascent_end, r.steps_climbed, r.steps_descended) == (
        "completed", "top_reached", 5, 5), r.to_dict()
    assert not r.fell and r.pauses <= 1, r.to_dict()
    assert r.final_offset_m is not None and r.final_offset_m <= 0.05, r.to_dict()


def test_its_cone_raises_the_lowest_rise_it_measures_a_tread_against() -> None:
    ideal = load_config("ideal")
    assert ideal.min_rise_for(0.5) == limits.min_step_rise_m(ideal)  # a level ray
    top = math.radians(45.0 / 8)  # one row of 5.625-degree zones, from level up
    ref = REFERENCE
    assert ref.front_cone_top_rad == pytest.approx(top)
    assert ref.min_rise_for(0.30) - ref.min_rise_for(0.26) == pytest.approx(0.04 * math.tan(top))
    assert limits.min_step_rise_m(ref) == pytest.approx(ref.min_rise_for(limits.min_tread_m(ref)))


def test_it_reaches_a_riser_below_010_m_behind_every_tread_up_to_040_m() -> None:
    # the riser must fill the row from level to 5.625 degrees up over the
    # tread and the approach's gap, from the sensor 0.038 m above the tread,
    # with 10 mm to spare: 0.048 + (T + 0.01) tan 5.625 degrees
    for mm in range(260, 401, 10):
        tread = mm / 1000
        reach = 0.03 + 0.008 + 0.01 + (tread + 0.01) * 0.098491
        assert REFERENCE.min_rise_for(tread) == pytest.approx(reach, abs=1e-5)
        assert REFERENCE.min_rise_for(tread) < 0.10, tread
    assert REFERENCE.min_rise_for(0.40) == pytest.approx(0.0884, abs=1e-4)
    shown = limits.derived(REFERENCE)
    assert shown["min_rise_behind_0.40_m"] == REFERENCE.min_rise_for(0.40) <= 0.10
    assert shown["min_step_rise_m"] == pytest.approx(0.0746, abs=1e-4)


def test_a_riser_too_low_for_the_long_tread_before_it_is_refused_and_it_comes_home() -> None:
    # 0.085 m rises behind 0.45 m treads: the first riser is climbed onto
    # (above min_step_rise_m), the next one is lower than the row needs to
    # measure the 0.45 m tread against (min_rise_for 0.093 m)
    events: list[Event] = []
    r = run_reference("[stairs]\ncount = 3\nrise = 0.085\ntread = 0.45\n[sensors]\nseed = 2\n",
                      events)
    assert (r.outcome, r.ascent_end, r.steps_climbed) == ("completed", "obstacle", 0), r.to_dict()
    assert not r.fell and r.final_offset_m is not None and r.final_offset_m <= 0.05
    assert any("too low" in e.message for e in events), [e.message for e in events]


def test_a_sweep_runs_on_another_robot_by_name() -> None:
    spec = load_spec(Path(__file__).parents[1] / "stairbot" / "inputs" / "sweeps" / "quick.toml")
    ideal = with_config(spec, "ideal")
    assert ideal.hash != spec.hash
    assert ideal.config_text is not None and 'front_model = "ideal"' in ideal.config_text
    assert "extends" not in ideal.config_text  # laid in: the cases stand on their own
    with pytest.raises(SpecError, match="no such file, nor a shipped robot"):
        with_config(spec, "lidar-bot")


def test_square_range_is_where_the_cone_rises_to_the_lowest_riser_it_climbs() -> None:
    # a level ray squares up from anywhere
    assert limits.square_range_m(load_config("ideal")) == math.inf
    ref = REFERENCE
    rise = limits.min_step_rise_m(ref)
    expected = (rise - ref.sensors.front_height) / math.tan(ref.front_cone_top_rad)
    assert limits.square_range_m(ref) == pytest.approx(expected)
    assert ref.SAFE_DISTANCE_IN_FRONT_OF_STEP < limits.square_range_m(ref) < 0.5


FAR_ASKEW = """
[stairs]
steps = [{rise = 0.1628, tread = 0.3012}, {rise = 0.1581, tread = 0.2983},
         {rise = 0.1607, tread = 0.3011}, {rise = 0.1613, tread = 0.2991}]
top = "wall"
width = 1.0
[start]
distance = 0.911426
yaw_deg = -18.640306
lateral = -0.066314
[sensors]
noise = 0.001
seed = 990114
"""


def test_far_and_askew_it_closes_in_squares_up_and_retraces_its_way_home() -> None:
    """Found by the envelope sweep: squared up 0.97 m away, where the cone
    reads a blend of the risers, the reference robot stood 11 deg askew and the
    standing rule ended the run in the approach.  Now it closes in to
    square_range_m (no further than its first reading allows), squares up
    there, climbs, and comes home the way it went: turning back the squaring
    turn before it backs the distance it closed in."""
    from stairbot.control.algorithm.phases import Phase

    events: list[Event] = []
    r = run_reference(FAR_ASKEW, events)
    assert (r.outcome, r.steps_climbed, r.steps_descended, r.pauses) == (
        "completed", 4, 4, 0), r.to_dict()
    assert r.final_offset_m is not None and r.final_offset_m <= 0.05, r.to_dict()
    labels = {e.phase for e in events}
    for phase in (Phase.CAL_CLOSE_IN, Phase.CAL_TURN_TO, Phase.DESCENT_FINISH_FLOOR):
        assert phase.label in labels
    closing = [e for e in events if "closing in before squaring up" in e.message]
    assert len(closing) == 1
    squared = [e for e in events if e.message.startswith("squared up")]
    square_range = limits.square_range_m(REFERENCE) + REFERENCE.algorithm.equal_tolerance
    assert squared and max(squared[0].data["SFR"], squared[0].data["SFL"]) < square_range


TOP_OF_A_FLIGHT = """
[stairs]
steps = [{rise = 0.153893, tread = 0.284283}, {rise = 0.153903, tread = 0.280612},
         {rise = 0.148586, tread = 0.279524}, {rise = 0.145488, tread = 0.280215}]
top = "landing"
width = 1.0
[start]
distance = 0.454258
yaw_deg = 13.048304
lateral = 0.038764
[sensors]
noise = 0.001
seed = 275795
"""


def test_at_the_top_segment_3_is_lowered_onto_its_tread_without_pushing() -> None:
    """Found by the envelope sweep: the VL53L0X pair reads a few mm above
    BACK_CLEARANCE standing (noise; its cone's slanted rays), so descent 2
    kept lowering segment 3 onto the tread it stood on and tipped segment 2
    15 deg nose down.  Now BACK_CLEARANCE is read within the pair's noise."""
    r = run_reference(TOP_OF_A_FLIGHT)
    assert (r.outcome, r.ascent_end, r.steps_climbed, r.steps_descended) == (
        "completed", "top_reached", 4, 4), r.to_dict()
    assert r.max_pitch_deg is not None and r.max_pitch_deg < 8.0, r.to_dict()


NINE_STEPS = """
[stairs]
top = "wall"
width = 1.0
steps = [{rise = 0.151992, tread = 0.316024}, {rise = 0.145985, tread = 0.319762},
         {rise = 0.151061, tread = 0.322781}, {rise = 0.153645, tread = 0.315707},
         {rise = 0.148681, tread = 0.316283}, {rise = 0.145012, tread = 0.315254},
         {rise = 0.15256, tread = 0.320094}, {rise = 0.146124, tread = 0.321481},
         {rise = 0.148392, tread = 0.323285}]
[start]
distance = 0.840602
yaw_deg = 11.250605
lateral = -0.070019
[sensors]
noise = 0.001
seed = 126550
"""


@pytest.fixture(scope="module")
def nine_steps() -> tuple[RunResult, list[Event]]:
    events: list[Event] = []
    return run_reference(NINE_STEPS, events), events


def test_backing_to_an_edge_stops_where_the_back_pair_saw_it(
        nine_steps: tuple[RunResult, list[Event]]) -> None:
    """Found by the envelope sweep (case 962 on tof): tab_length_to_edge of
    step 6, read on the way up, was 1.4 cm long; backing up to it, the
    robot tipped back 15 deg off segment 2's rear wheels.  The back pair
    now bounds the backing: edge_clearance_m past where it saw the drop."""
    from stairbot.control.algorithm.edge_measure import edge_clearance_m

    assert edge_clearance_m(REFERENCE) == pytest.approx(0.075 - 0.01 - 0.0185 + 0.016 + 0.006
                                                       + REFERENCE.wheel_speed_m_s * 0.030)
    r, _ = nine_steps
    assert (r.outcome, r.steps_climbed, r.steps_descended) == ("completed", 9, 9), r.to_dict()
    assert r.max_pitch_deg is not None and r.max_pitch_deg < 8.0, r.to_dict()


def test_after_a_long_flight_it_comes_home(nine_steps: tuple[RunResult, list[Event]]) -> None:
    """Found by the envelope sweep (and the shipped scenario
    more_than_10_steps on tof): squared up within the pair's noise, the robot
    climbed part of a flight 1.7 deg to one side and part 1.5 deg to the
    other, and came down squared to yet another heading: it ended 6-10 cm to
    the side of its start.  A squaring turn is now checked standing on all
    wheels (and corrected), and descent 1 turns back to the heading it
    climbed each step with (tests/core/test_calibration.py)."""
    r, _ = nine_steps
    assert r.final_offset_m is not None and r.final_offset_m <= 0.05, r.to_dict()


SHORT_TREADS = """
[stairs]
top = "landing"
width = 1.0
steps = [{rise = 0.141086, tread = 0.272629}, {rise = 0.143831, tread = 0.269382},
         {rise = 0.142043, tread = 0.265423}, {rise = 0.140801, tread = 0.271245},
         {rise = 0.13901, tread = 0.274156}, {rise = 0.140918, tread = 0.267896},
         {rise = 0.138306, tread = 0.268265}, {rise = 0.139005, tread = 0.265219},
         {rise = 0.135622, tread = 0.26819}]
[start]
distance = 0.615084
yaw_deg = -10.305475
lateral = -0.141991
[sensors]
noise = 0.001
seed = 10037
"""


def test_backing_off_a_short_tread_is_bounded_by_the_edge_too() -> None:
    """Found by the envelope sweep (case 749 on tof): on treads a centimetre
    longer than the robot's minimum, descent 1's back-off (the seed's
    approach turns) already took segment 3 past the edge; backing up to the
    edge then allowed edge_clearance_m more from there, and the robot tipped
    back (the tilt supervisor stopped it at 145 deg/s).  The back pair now
    bounds the back-off as well, from where it first saw the drop."""
    from stairbot.control.algorithm.phases import Phase

    events: list[Event] = []
    r = run_reference(SHORT_TREADS, events)
    assert (r.outcome, r.steps_climbed, r.steps_descended) == ("completed", 9, 9), r.to_dict()
    assert r.max_pitch_deg is not None and r.max_pitch_deg < 8.0, r.to_dict()
    seen = [e for e in events if e.message.startswith("SBR/SBL see the edge")]
    assert len(seen) == 8  # every step but the top one, which needs no descent 1
    assert all(e.phase == Phase.DESCENT_BACK_OFF.label for e in seen)


OPEN_SIDE = """
[stairs]
top = "wall"
width = 1.0
side_wall = "none"
count = 3
rise = 0.2
tread = 0.32
[start]
distance = 0.910323
yaw_deg = 19.099647
lateral = 0.148694
[sensors]
noise = 0.001
seed = 519449
"""


def test_one_beam_off_the_open_side_of_a_flight_is_case_2_not_a_side_wall() -> None:
    """Found by the envelope sweep (case 1813 on tof): 19 deg askew near the
    open side of a flight, SFL read nothing past its side, SFR the riser;
    taken for a side wall (case 2W), the robot turned away from the riser
    until it gave up.  One beam reading nothing is case 2: it turns towards
    the riser."""
    events: list[Event] = []
    r = run_reference(OPEN_SIDE, events)
    assert r.outcome == "completed" and r.steps_climbed == 3, r.to_dict()
    assert r.final_offset_m is not None and r.final_offset_m <= 0.05, r.to_dict()
    cases = [e.data.get("case") for e in events if "case" in e.data]
    assert cases[0] == "2", cases


SETTLING = """
[stairs]
top = "landing"
width = 1.0
steps = [{rise = 0.171083, tread = 0.313664}, {rise = 0.173967, tread = 0.313127},
         {rise = 0.173358, tread = 0.311512}]
[start]
distance = 0.798965
yaw_deg = 15.465028
lateral = -0.115377
[sensors]
noise = 0.001
seed = 89926
"""


def test_the_start_reading_is_taken_once_segment_1_has_settled() -> None:
    """Found by the envelope sweep (case 1297 on tof): read the tick segments
    1 and 3 came down, the start reading caught the cone pitched onto the
    floor (0.202 m for 0.327 m) and descent 7 stopped 0.125 m short."""
    events: list[Event] = []
    r = run_reference(SETTLING, events)
    start = [e for e in events if e.message.startswith("start position")]
    assert len(start) == 1 and start[0].data["start_reading"] > 0.3
    assert (r.outcome, r.steps_climbed, r.steps_descended) == ("completed", 3, 3), r.to_dict()
    assert r.final_offset_m is not None and r.final_offset_m <= 0.05, r.to_dict()
