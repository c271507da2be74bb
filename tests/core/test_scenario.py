"""Scenarios: the schema, the shipped files, expectations, and errors that name
the file, the field and what is allowed."""

from __future__ import annotations

from pathlib import Path

import pytest

from stairbot.errors import ScenarioError
from stairbot.inputs.scenario import (
    Expect,
    expectation_mismatches,
    load_scenario,
    parse_scenario,
    shipped_scenarios,
)

ISSUE_EXAMPLE = """
[stairs]
count = 5
rise = 0.17
tread = 0.28
top = "landing"
width = 1.0
side_wall = "none"
[start]
distance = 0.5
yaw_deg = 0.0
lateral = 0.0
[sensors]
noise = 0.001
seed = 1
[[faults]]
at = 20.0
sensor = "SFL"
kind = "offset"
offset = 0.05
duration = 3.0
[expect]
outcome = "completed"
ascent_end = "top_reached"
steps_climbed = 5
"""


def test_the_schema_example_of_the_issue_parses() -> None:
    s = parse_scenario(ISSUE_EXAMPLE, "example.toml")
    assert len(s.steps) == 5 and s.steps[0].rise == 0.17 and s.steps[0].tread == 0.28
    assert s.name == "example"
    assert s.faults[0].sensor == "SFL" and s.faults[0].duration == 3.0
    assert s.expect is not None and s.expect.steps_climbed == 5


def test_a_stuck_fault_parses_with_or_without_a_duration() -> None:
    s = parse_scenario("[[faults]]\nat = 20.0\nsensor = 'SBR'\nkind = 'stuck'\n"
                       "[[faults]]\nat = 30.0\nsensor = 'SFL'\nkind = 'stuck'\n"
                       "duration = 2.5\n", "stuck.toml")
    assert [(f.sensor, f.kind, f.at, f.duration, f.offset) for f in s.faults] == [
        ("SBR", "stuck", 20.0, None, 0.0), ("SFL", "stuck", 30.0, 2.5, 0.0)]


def test_default_is_five_residential_steps_then_a_landing() -> None:
    s = load_scenario()
    assert [(st.rise, st.tread) for st in s.steps] == [(0.17, 0.28)] * 5
    assert s.top == "landing"
    assert s.expect is not None and s.expect.outcome == "completed"


def test_left_out_keys_take_the_default_stairs() -> None:
    assert parse_scenario("", "empty.toml").steps == load_scenario().steps
    s = parse_scenario("[stairs]\ncount = 2\n", "two.toml")
    assert [(st.rise, st.tread) for st in s.steps] == [(0.17, 0.28)] * 2


def test_explicit_steps_and_open_floor() -> None:
    s = parse_scenario("[stairs]\nsteps = [{rise = 0.15, tread = 0.3}, {rise = 0.18, "
                       "tread = 0.26}]\n", "mixed.toml")
    assert [st.rise for st in s.steps] == [0.15, 0.18]
    assert parse_scenario("[stairs]\ncount = 0\n", "open.toml").steps == ()


def test_every_shipped_scenario_is_valid_and_loads_by_name() -> None:
    names = shipped_scenarios()
    assert "default" in names and len(names) >= 14
    for name in names:
        s = load_scenario(name)
        assert s.expect is not None, f"{name} has no [expect]"
        assert s.description, f"{name} has no description"


def test_a_path_is_read_as_a_file(tmp_path: Path) -> None:
    p = tmp_path / "mine.toml"
    p.write_text('name = "mine"\n[stairs]\ncount = 2\nrise = 0.16\ntread = 0.3\n')
    assert load_scenario(p).name == "mine"
    assert len(load_scenario(str(p)).steps) == 2


@pytest.mark.parametrize(
    ("text", "field", "words"),
    [
        ("[stairs]\ncolour = 'red'\n", "stairs.colour", "allowed keys here: count, rise"),
        ("[stairs]\ncount = 3\nrise = -0.17\ntread = 0.28\n", "stairs.rise", ">= 0.005 and <= 1"),
        ("[stairs]\ncount = 3\nrise = 'high'\ntread = 0.28\n", "stairs.rise", "a number"),
        ("[stairs]\ncount = 2.5\nrise = 0.17\ntread = 0.28\n", "stairs.count", "whole number"),
        ("[stairs]\ntop = 'roof'\nrise = 0.17\ntread = 0.28\n", "stairs.top", "'landing', 'wall'"),
        ("[stairs]\ncount = 0\ntop = 'wall'\n", "stairs.top", "at least one step"),
        ("[stairs]\ncount = 2\nrise = 0.1\ntread = 0.3\nsteps = [{rise = 0.1, tread = 0.3}]\n",
         "stairs.steps", "not both"),
        ("[stairs]\nsteps = [{rise = 0.1, tread = 0.0}]\n", "stairs.steps[0].tread",
         ">= 0.01 and <= 10"),
        ("[start]\nyaw_deg = 120\n", "start.yaw_deg", "<= 80"),
        ("[start]\nlateral = 0.7\n", "start.lateral", "half the width"),
        ("[start]\non = 'roof'\n", "start.on", "'floor', 'top'"),
        ("[stairs]\ncount = 0\n[start]\non = 'top'\n", "start.on", "at least one step"),
        ("[stairs]\ntop = 'wall'\n[start]\non = 'top'\n", "start.on", "on a landing"),
        ("[start]\non = 'top'\ndistance = 2.5\n", "start.distance", "up to 2.0 m"),
        ("[[faults]]\nat = 1.0\nsensor = 'SFX'\nkind = 'error'\n", "faults[0].sensor", "'SFL'"),
        ("[[faults]]\nat = 1.0\nsensor = 'SFL'\n", "faults[0].kind", "required"),
        ("[[faults]]\nat = 1.0\nsensor = 'SFL'\nkind = 'offset'\n", "faults[0].offset",
         "non-zero"),
        ("[[faults]]\nat = 1.0\nsensor = 'SFL'\nkind = 'stuck'\noffset = 0.02\n",
         "faults[0].offset", "repeat its last measurement as new ('stuck')"),
        ("[[faults]]\nat = 1.0\nsensor = 'SFL'\nkind = 'stuk'\n", "faults[0].kind",
         "'stuck'"),
        ("[[faults]]\nat = 1.0\nsensor = 'SFL'\nkind = 'stuck'\nduration = 0.0\n",
         "faults[0].duration", "> 0"),
        ("[expect]\noutcome = 'won'\n", "expect.outcome", "'completed'"),
        ("speed = 3\n", "speed", "allowed keys here: name, description"),
    ],
)
def test_bad_scenarios_name_the_file_the_field_and_what_is_allowed(
        text: str, field: str, words: str) -> None:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, "stairs.toml")
    assert info.value.source == "stairs.toml"
    assert info.value.field == field
    assert words in str(info.value)


def test_not_toml_and_missing_files_and_unknown_names(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError, match="not valid TOML"):
        parse_scenario("[stairs\n", "x.toml")
    with pytest.raises(ScenarioError, match="cannot read"):
        load_scenario(tmp_path / "none.toml")
    with pytest.raises(ScenarioError, match="shipped: .*default"):
        load_scenario("no_such_scenario")


RESULT = {"outcome": "completed", "ascent_end": "top_reached", "steps_climbed": 5,
          "steps_descended": 5, "pauses": 0, "error": None, "final_offset_m": 0.01}


def test_expectations_met_and_missed() -> None:
    assert expectation_mismatches(Expect(outcome="completed", steps_climbed=5), RESULT) == []
    assert expectation_mismatches(None, RESULT) == []
    missed = expectation_mismatches(Expect(steps_climbed=4, ascent_end="obstacle"), RESULT)
    assert missed == ["steps_climbed: expected 4, got 5",
                      "ascent_end: expected 'obstacle', got 'top_reached'"]
    assert expectation_mismatches(None, {**RESULT, "outcome": "error"}) == [
        "outcome: expected 'completed', got 'error'"]
    assert expectation_mismatches(Expect(ascent_end="none"), {**RESULT, "ascent_end": None}) == []
    assert expectation_mismatches(Expect(max_final_offset_m=0.005), RESULT)
    assert expectation_mismatches(Expect(error_contains="floor"),
                                  {**RESULT, "error": "Floor not found"}) == []


def test_a_start_on_the_top_expects_no_climb() -> None:
    for expect in ("steps_climbed = 2", "ascent_end = 'top_reached'"):
        with pytest.raises(ScenarioError) as info:
            parse_scenario(f"[start]\non = 'top'\n[expect]\n{expect}\n", "top.toml")
        assert info.value.field == "expect" and "climbs nothing" in str(info.value)
    parse_scenario("[start]\non = 'top'\n[expect]\nsteps_climbed = 0\nascent_end = 'none'\n",
                   "top.toml")
