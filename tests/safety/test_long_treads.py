"""Long treads (stairbot.control.algorithm.long_tread): past FAR_TREAD_M the robot
climbs a riser lower than the front cone's rule asks when its readings held
as segment 1 rose, refuses it when they grew, and drives onto and off such a
tread by turns."""

from __future__ import annotations

from pathlib import Path

import pytest
import simrun

from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind
from stairbot.inputs.scenario import parse_scenario

REFERENCE = load_config("reference")
VL53L1X_FRONT = load_config(str(Path(__file__).parents[1] / "robots" / "vl53l1x_front.toml"))


def flight(rise: float, tread: float, top: str = "landing", seed: int = 1) -> str:
    return (f"[stairs]\ncount = 3\nrise = {rise}\ntread = {tread}\ntop = '{top}'\n"
            f"[start]\ndistance = 0.5\n[sensors]\nseed = {seed}\n")


def infos(events: list[Event]) -> list[str]:
    return [e.message for e in events if e.kind is EventKind.INFO]


@pytest.mark.parametrize(("robot", "rise"), [("reference", 0.11), ("vl53l1x_front", 0.17)])
def test_a_long_tread_before_a_riser_the_whole_cone_sees_is_climbed_by_turns(
        robot: str, rise: float) -> None:
    """Risers 0.7 m apart, lower than min_rise_for(0.7) asks (0.118 m of the
    reference robot's row of zones, 0.24 m of the VL53L1X's 15-degree cone),
    which refused them before: the readings hold, and the drives go by
    turns."""
    config = REFERENCE if robot == "reference" else VL53L1X_FRONT
    assert rise < config.min_rise_for(0.7)
    events: list[Event] = []
    result = simrun.run_sim(config, parse_scenario(flight(rise, 0.7), "<t>"), events)
    assert (result.outcome, result.steps_climbed, result.steps_descended) == \
        ("completed", 3, 3), result.to_dict()
    assert result.final_offset_m is not None and result.final_offset_m < 0.05
    assert not result.fell
    told = infos(events)
    assert sum("a wall, or a riser the whole cone sees" in m for m in told) == 2
    assert sum("the drives onto the step go by turns" in m for m in told) == 2


@pytest.mark.parametrize(("robot", "rise"), [("reference", 0.09), ("vl53l1x_front", 0.14)])
def test_a_long_tread_before_a_riser_the_cone_sees_over_is_refused(
        robot: str, rise: float) -> None:
    """Risers 0.6 m apart, lower than min_rise_for(0.6): the top of the
    view takes in what lies beyond, the reading is centimetres long, and it
    grows as segment 1 rises."""
    config = REFERENCE if robot == "reference" else VL53L1X_FRONT
    assert rise < config.min_rise_for(0.6)
    for seed in (1, 2):
        events: list[Event] = []
        scenario = parse_scenario(flight(rise, 0.6, seed=seed), "<t>")
        result = simrun.run_sim(config, scenario, events)
        assert (result.outcome, result.ascent_end, result.steps_climbed) == \
            ("completed", "obstacle", 0), result.to_dict()
        assert any("the cone sees over it" in m for m in infos(events))


def test_a_landing_as_deep_as_most_homes_is_climbed_onto_and_left_by_turns() -> None:
    """A 0.9 m landing before a wall on the reference robot (no side pair):
    it climbs onto it, refuses the wall, and comes home."""
    events: list[Event] = []
    text = ("[stairs]\nsteps = [{rise = 0.17, tread = 0.28}, {rise = 0.17, tread = 0.28}, "
            "{rise = 0.17, tread = 0.9}]\ntop = 'wall'\n[start]\ndistance = 0.5\n")
    result = simrun.run_sim(REFERENCE, parse_scenario(text, "<t>"), events)
    assert (result.outcome, result.ascent_end, result.steps_climbed,
            result.steps_descended) == ("completed", "obstacle", 3, 3), result.to_dict()
    assert result.final_offset_m is not None and result.final_offset_m < 0.05


def test_a_tab_ascent_7_missed_is_found_by_the_back_pair_on_the_way_down() -> None:
    """SFR reads past LENGTH_OF_INFINITY over ascent 7 and 8 of step 1 (as
    the ir robot's beam did with a riser 0.75 m away): the tab is not
    measured, ascent 8 waits TAB_WAIT_S for it and goes on, and descent 1
    finds step 1's edge by the back pair alone (it stopped with "the edge of
    the step cannot be found" before)."""
    text = ("[stairs]\ncount = 2\nrise = 0.17\ntread = 0.28\n"
            "[[faults]]\nat = 47.6\nsensor = 'SFR'\nkind = 'offset'\noffset = 1.5\n"
            "duration = 3.5\n")
    events: list[Event] = []
    result = simrun.run_sim(REFERENCE, parse_scenario(text, "<t>"), events)
    assert (result.outcome, result.steps_climbed, result.steps_descended) == \
        ("completed", 2, 2), result.to_dict()
    assert result.final_offset_m is not None and result.final_offset_m < 0.05
    told = infos(events)
    assert any(m.startswith("tab_length_to_edge[0] not measured: SFR/SFL read") for m in told)
    assert any(m.startswith("SBR/SBL see the edge") for m in told)


RED_FLIGHT = ("[stairs]\nsteps = [{rise = 0.17, tread = 0.28}, {rise = 0.17, tread = 0.7}, "
              "{rise = 0.14, tread = 0.28}, {rise = 0.17, tread = 0.28}]\ntop = 'landing'\n"
              "[sensors]\nseed = 6\n")


def test_a_front_sensor_reading_short_while_the_tab_of_a_long_tread_is_read_stops_the_robot(
        ) -> None:
    """The red team: SFL 0.13 m short through ascent 7 of the 0.7 m step.
    With the standing rule off there (the drives go by turns), the tab was
    stored 65 mm short and descent 1 stopped segment 3 short of the edge:
    tilt stop nose down two steps higher.  Ascent 7 reads the tab, and the
    rule is armed in it."""
    text = RED_FLIGHT + ("[[faults]]\nat = 71.5\nsensor = 'SFL'\nkind = 'offset'\n"
                         "offset = -0.13\nduration = 9\n")
    result = simrun.run_sim(REFERENCE, parse_scenario(text, "<t>"))
    assert result.outcome == "error" and not result.fell, result.to_dict()
    assert "still disagree" in str(result.error) and "ascent 7" in str(result.error)
    assert result.steps_climbed == 1


@pytest.mark.parametrize(("offset", "said"), [
    (0.1, "SBL judged biased"),  # reads a "drop" far short of the rise, flat
    (0.17, "SBL reads the drop, SBR still the floor"),  # reads the rise's drop
])
def test_a_back_sensor_reading_the_drop_far_before_the_other_stops_the_robot_on_the_tread(
        offset: float, said: str) -> None:
    """The red team: SBL reading long as the robot backs up to the 0.7 m
    step's edge reads a drop 0.2 m before SBR; placed half-way between the
    two, the crossing left the robot short of the edge and it tipped nose
    down lowering segment 3.  A reading far short of the step's rise that
    holds flat while the robot backs is no edge: SBL is judged biased
    (bias_flat.py).  One that reads the rise, as a real drop does, more
    than MAX_EDGE_YAW_RAD's worth before its partner: the robot stops
    where it stands.  Either way it stops, without consent, on the tread."""
    text = RED_FLIGHT + ("[[faults]]\nat = 193.1\nsensor = 'SBL'\nkind = 'offset'\n"
                         f"offset = {offset}\nduration = 6\n")
    result = simrun.run_sim(REFERENCE, parse_scenario(text, "<t>"))
    assert result.outcome == "error" and not result.fell, result.to_dict()
    assert said in str(result.error), result.error
    assert result.max_pitch_deg is not None and result.max_pitch_deg < 8.0
