"""``stairbot sweep SPEC --boundary AXIS``: the search (scan and k-section)
on fake probes, monotonic and not; the axis, range and points a spec gives;
the published limits; and one small real search on the simulated robot."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from stairbot.sweep.axes import SpecError
from stairbot.sweep.bisect import changes, scan_values, search
from stairbot.sweep.boundary import MAX_POINTS, Published, points, published, target
from stairbot.sweep.boundary_run import PointResult, behaviour, lines, point_dict, strip
from stairbot.sweep.spec import parse_spec

ROOT = Path(__file__).parents[2]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


def sweep(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "stairbot", "sweep", *args], cwd=ROOT,
                          env=ENV, capture_output=True, text=True, timeout=600)


class Fake:
    """A probe function: behaviour by rule, every call's batch kept."""

    def __init__(self, rule: Any) -> None:
        self.rule = rule
        self.batches: list[list[float]] = []

    def __call__(self, values: list[float]) -> list[str]:
        self.batches.append(list(values))
        return [self.rule(v) for v in values]


def step_at(edge: float) -> Any:
    return lambda v: "climbed" if v < edge else "refused"


# -- the search, on fake probes ----------------------------------------------------


@pytest.mark.parametrize("per_round", [1, 2, 3])
def test_a_monotonic_change_is_bracketed_within_the_tolerance(per_round: int) -> None:
    fake = Fake(step_at(0.20137))
    found = search(scan_values(0.05, 0.25, 12), fake, 0.001, per_round)
    assert found.monotonic and not found.exhausted
    [b] = found.brackets
    assert b.low < 0.20137 <= b.high and b.width <= 0.001
    assert (b.low_is, b.high_is) == ("climbed", "refused")
    # the scan first, then per_round probes a round in the one open bracket
    assert len(fake.batches[0]) == 12
    assert all(len(batch) == per_round for batch in fake.batches[1:])
    assert len(found.probes) == sum(len(x) for x in fake.batches)


def test_more_probes_a_round_take_fewer_rounds() -> None:
    one = search([0.0, 1.0], Fake(step_at(0.3141)), 0.001, 1)
    two = search([0.0, 1.0], Fake(step_at(0.3141)), 0.001, 2)
    assert two.rounds < one.rounds
    assert one.brackets[0].low < 0.3141 <= one.brackets[0].high
    assert two.brackets[0].low < 0.3141 <= two.brackets[0].high


def test_both_rise_limits_are_found_each_to_the_tolerance() -> None:
    # refused below the low-rise rule, climbed between, refused above the rise limit
    fake = Fake(lambda v: "climbed" if 0.0746 <= v < 0.2013 else "refused")
    found = search(scan_values(0.045, 0.232, 12), fake, 0.001, 2)
    low, high = found.brackets
    assert (low.low_is, low.high_is) == ("refused", "climbed")
    assert low.low < 0.0746 <= low.high and low.width <= 0.001
    assert high.low < 0.2013 <= high.high and high.width <= 0.001
    assert found.monotonic  # two changes, each a change of its own


def test_a_non_monotonic_bracket_is_reported_not_hidden() -> None:
    # an island of refusals (0.09-0.11) inside what the scan saw as one change
    fake = Fake(lambda v: "refused" if 0.09 <= v <= 0.11 or v >= 0.25 else "climbed")
    found = search([0.0, 0.3], fake, 0.001, 2)
    assert not found.monotonic
    tangle = found.tangles[0]
    assert (tangle.low, tangle.high) == (0.0, 0.3)
    assert changes([c for _, c in tangle.probes]) == 3
    # every change is narrowed on: the island's two edges and the real one
    edges = sorted(b.middle for b in found.brackets)
    assert len(edges) == 3
    assert abs(edges[0] - 0.09) <= 0.001 and abs(edges[1] - 0.11) <= 0.001
    assert abs(edges[2] - 0.25) <= 0.001


def test_the_report_says_non_monotonic() -> None:
    fake = Fake(lambda v: "refused" if 0.09 <= v <= 0.11 or v >= 0.25 else "climbed")
    spec = parse_spec('[axes]\n"stairs.count" = 1\n', "x.toml", ROOT)
    t = target(spec, "stairs.rise", None, None)
    found = search([0.0, 0.3], fake, 0.001, 2)
    r = PointResult(points(spec, "stairs.rise")[0], found, [], 0)
    d = point_dict(t, r)
    text = "\n".join(lines(t, 0, 1, r, d))
    assert not d["monotonic"] and d["non_monotonic"][0]["low"] == 0.0
    assert "NON-MONOTONIC in [0.0000, 0.3000]" in text
    # three changes where the rules (here: none given) make fewer
    assert d["extra_changes"] == 3 and "MORE CHANGES THAN PUBLISHED" in text


def test_no_change_is_said_plainly() -> None:
    found = search([0.0, 0.5, 1.0], Fake(lambda v: "climbed"), 0.001, 2)
    assert found.brackets == [] and len(found.probes) == 3
    spec = parse_spec("", "x.toml", ROOT)
    t = target(spec, "stairs.rise", None, None)
    r = PointResult(points(spec, "stairs.rise")[0], found, [], 0)
    assert "no change of behaviour" in "\n".join(lines(t, 0, 1, r, point_dict(t, r)))


def test_the_probe_budget_stops_a_search_and_says_so() -> None:
    found = search([0.0, 1.0], Fake(step_at(0.5)), 1e-9, 2, max_probes=10)
    assert found.exhausted and len(found.probes) <= 10
    assert found.brackets[0].width > 1e-9


def test_an_integer_axis_ends_on_neighbours() -> None:
    found = search(scan_values(1, 12, 12, integer=True), Fake(step_at(7)), 0.5, 2,
                   integer=True)
    [b] = found.brackets
    assert (b.low, b.high) == (6.0, 7.0)


def test_wrong_is_told_apart_by_what_the_robot_did() -> None:
    facts = {"expected_steps": 3}
    climbed = {"verdict": "wrong", "facts": facts,
               "result": {"outcome": "completed", "steps_climbed": 3}}
    refused = {"verdict": "wrong", "facts": facts,
               "result": {"outcome": "completed", "steps_climbed": 0}}
    assert behaviour(climbed) == "climbed" and behaviour(refused) == "refused"
    assert behaviour({"verdict": "stranded"}) == "stranded"


# -- the axis, the points, the published limits -------------------------------------


def test_a_bad_axis_name_is_one_clear_message() -> None:
    proc = sweep("sweeps/quick.toml", "--boundary", "stairs.colour")
    assert proc.returncode == 2
    [line] = proc.stderr.strip().splitlines()
    assert "stairs.colour" in line and "allowed:" in line
    assert "stairs.rise" in line and "stairs.tread" in line and "start.yaw_deg" in line
    assert "Traceback" not in proc.stderr


def test_a_tolerance_wider_than_the_range_is_refused() -> None:
    spec = parse_spec('[axes]\n"stairs.rise" = [0.19, 0.21]\n', "x.toml", ROOT)
    with pytest.raises(SpecError, match="--tolerance 50:"):
        target(spec, "stairs.rise", 50.0, None)
    assert target(spec, "stairs.rise", 2.0, None).tolerance == pytest.approx(0.002)
    assert target(spec, "stairs.rise", None, None).scan == (0.19, 0.21)


def test_every_value_of_another_grid_axis_is_a_point() -> None:
    spec = parse_spec('[sweep]\ncases = 2\n[axes]\n"stairs.rise" = [0.1, 0.2]\n'
                      '"stairs.tread" = [0.26, 0.3]\n"stairs.count" = [2, 3]\n'
                      '"start.yaw_deg" = { uniform = [-5, 5] }\n', "x.toml", ROOT)
    pts = points(spec, "stairs.rise")
    assert [(p.held["stairs.tread"], p.held["stairs.count"]) for p in pts] == [
        (0.26, 2), (0.26, 3), (0.3, 2), (0.3, 3)]
    for p in pts:  # each point's first sample, the axis left out
        assert spec.axis_values(p.base)["start.yaw_deg"] == p.held["start.yaw_deg"]
        assert "stairs.rise" not in p.held
    many = parse_spec('[axes]\n"stairs.count" = { range = [1, 17, 1] }\n', "x.toml", ROOT)
    with pytest.raises(SpecError, match=f"at most {MAX_POINTS}"):
        points(many, "stairs.rise")


def test_the_published_limits_are_named() -> None:
    spec = parse_spec('[axes]\n"stairs.count" = 3\n"stairs.tread" = 0.28\n', "x.toml", ROOT)
    t = target(spec, "stairs.rise", None, None)
    pubs = published(spec, 0, t)
    names = [p.name for p in pubs]
    assert names[-1] == "max_step_rise_m" and pubs[-1].value == pytest.approx(0.202, abs=1e-5)
    assert (pubs[-1].below, pubs[-1].above) == ("inside", "outside")
    assert names[0].startswith("min_rise_for(") or names[0] == "min_step_rise_m"
    tread = published(spec, 0, target(spec, "stairs.tread", None, None))
    assert [p.name for p in tread] == ["min_tread_m"]
    assert tread[0].value == pytest.approx(0.26, abs=1e-5)


# -- one real search ------------------------------------------------------------------

SMALL = """
[sweep]
name = "small"
[axes]
"stairs.count" = 1
"start.distance" = 0.3
"stairs.rise" = [0.194, 0.21]
"""


def test_a_rise_boundary_on_the_simulated_robot(tmp_path: Path) -> None:
    spec_file = tmp_path / "small.toml"
    spec_file.write_text(SMALL, "utf-8")
    out = tmp_path / "out"
    proc = sweep(str(spec_file), "--boundary", "stairs.rise", "-j", "2", "--out", str(out),
                 "-q")
    report = json.loads((out / "boundary.json").read_text("utf-8"))
    records = [json.loads(x) for x in (out / "cases.jsonl").read_text("utf-8").splitlines()]
    [pt] = report["points"]
    [b] = pt["brackets"]
    assert b["width"] <= 0.001 + 1e-9 and b["within_tolerance"]
    assert b["last"]["behaviour"] != b["first"]["behaviour"]
    assert b["published"]["name"] == "max_step_rise_m"
    assert b["difference"] == pytest.approx(b["middle"] - 0.202, abs=1e-9)
    # each probe a line with its axis value, verdict and margins
    assert len(records) == pt["probes"] == report["probes"]
    by_value = {r["axes"]["stairs.rise"]: r for r in records}
    assert behaviour(by_value[b["last"]["value"]]) == b["last"]["behaviour"]
    assert behaviour(by_value[b["first"]["value"]]) == b["first"]["behaviour"]
    for r in records:
        assert r["facts"]["boundary"]["axis"] == "stairs.rise"
        assert r["result"]["margins"]["stroke_m"] is not None
    failing = [r for r in records if r["verdict"] not in ("climbed", "refused")]
    assert proc.returncode == (1 if failing else 0), proc.stderr
    assert "published max_step_rise_m 0.2020" in proc.stdout


def test_the_strip_shows_the_probes_and_the_published_limits() -> None:
    spec = parse_spec('[axes]\n"stairs.rise" = [0.1, 0.3]\n', "x.toml", ROOT)
    t = target(spec, "stairs.rise", None, None)
    probes = [(0.1, "climbed"), (0.2, "climbed"), (0.2001, "refused"), (0.3, "refused")]
    row, marks = strip(t, probes, [Published(0.2, "inside", "outside", "max_step_rise_m")])
    cells = row.split()[1]
    assert cells[0] == "C" and cells[-1] == "R" and "!" in cells  # two behaviours, one cell
    assert marks.index("^") == row.index("!")


def test_a_change_to_a_failing_behaviour_is_a_finding_not_a_limit() -> None:
    # stranded on the lowest risers, refused, then climbed: the rules publish one change
    fake = Fake(lambda v: "stranded" if v < 0.02 else "refused" if v < 0.07 else "climbed")
    spec = parse_spec('[axes]\n"stairs.rise" = [0.01, 0.1]\n', "x.toml", ROOT)
    t = target(spec, "stairs.rise", None, None)
    found = search([0.01, 0.04, 0.1], fake, 0.001, 2)
    pub = [Published(0.075, "outside", "inside", "min_rise_for(0.28)")]
    r = PointResult(points(spec, "stairs.rise")[0], found, pub, 0)
    d = point_dict(t, r)
    low, high = d["brackets"]
    assert low["failing_side"] == ["last"] and "published" not in low
    assert high["published"]["name"] == "min_rise_for(0.28)"
    # it climbs from 0.07, below the 0.075 the rules need: better than published
    assert high["published_is"] == "conservative" and d["extra_changes"] == 0
    text = "\n".join(lines(t, 0, 1, r, d))
    assert "FAILING (stranded) on one side" in text and "MORE CHANGES" not in text
