"""Sweep specs: parsing, case generation and the checks that stop a bad spec
before any case runs (exit 2, one line naming the field and what is allowed)."""

from __future__ import annotations

import math
import sys
import types
from dataclasses import replace
from pathlib import Path

import msgspec
import pytest

from stairbot.cli import main
from stairbot.control.robot_config import load_config, parse_config
from stairbot.inputs.scenario import parse_scenario
from stairbot.sweep.cases import Case, build_case, check_spec
from stairbot.sweep.execute import open_executor
from stairbot.sweep.spec import Rules, parse_spec
from stairbot.sweep.worker import run_case
from stairbot.sweep.zones import REST_S, first_sight, sight_margin, zone

VL53L1X_FRONT = load_config(str(Path(__file__).parents[1] / "robots" / "vl53l1x_front.toml"))

GOOD = """
[sweep]
name = "t"
seed = 3
cases = 4
[axes]
"stairs.rise" = { range = [0.15, 0.17, 0.01] }
"stairs.tread" = [0.26, 0.30]
"start.yaw_deg" = { uniform = [-10, 10] }
"sensors.seed" = { randint = [1, 1000] }
"config.masses.second_module" = { normal = [1.3, 0.05] }
"stairs.rise_jitter" = 0.004
"""


def test_grid_times_samples_and_every_case_reproducible_from_hash_and_index() -> None:
    a, b = parse_spec(GOOD, "a.toml"), parse_spec(GOOD, "b.toml")
    assert a.hash == b.hash and a.grid_size == 6 and a.total == 24
    assert [c.scenario_text for c in check_spec(a)] == [c.scenario_text for c in check_spec(b)]
    case = build_case(a, 17)
    assert case == build_case(b, 17) and case.config_text is not None
    # the grid point is index // cases, the last grid axis varying fastest
    assert (case.axes["stairs.rise"], case.axes["stairs.tread"]) == (0.17, 0.26)
    steps = parse_scenario(case.scenario_text, "x").steps
    assert all(abs(s.rise - 0.17) <= 0.004 for s in steps) and len({s.rise for s in steps}) > 1
    # another seed draws other values; the same seed the same, whatever the file name
    other = parse_spec(GOOD.replace("seed = 3", "seed = 4"), "a.toml")
    assert build_case(other, 17).axes["start.yaw_deg"] != case.axes["start.yaw_deg"]


def test_last_tread_under_a_landing_does_not_count_but_under_a_wall_it_does() -> None:
    cfg, rules = load_config(), Rules()
    text = "[stairs]\ncount = {n}\nrise = 0.17\ntread = 0.22\ntop = '{top}'\n"
    one = parse_scenario(text.format(n=1, top="landing"), "x")
    assert zone(one, cfg, rules)[0] == "inside"
    assert zone(parse_scenario(text.format(n=1, top="wall"), "x"), cfg, rules)[0] == "outside"
    assert zone(parse_scenario(text.format(n=2, top="landing"), "x"), cfg, rules)[0] == "outside"
    band = parse_scenario("[stairs]\ncount = 2\nrise = 0.20\ntread = 0.3\n", "x")
    assert zone(band, cfg, rules)[0] == "band"


QUARTER_TURN = """
[stairs]
count = 3
rise = 0.17
tread = 0.28
width = {width}
[start]
distance = 0.5
yaw_deg = -5.686636
lateral = -0.036316
[landing]
turn = "right"
depth = 1.02
count = 3
"""


def test_a_landing_allows_for_the_drift_the_squarings_tolerance_leaves() -> None:
    """Squared up within equal_tolerance the robot may stand 2.9° askew
    (5 mm over the pair's 0.1 m), and keeps it up the flight: over the 2 m to
    a 1.02 m landing's wall that is 0.1 m across, so a 0.6 m wide flight
    climbed 36 mm to the side may leave less room to turn than the robot
    needs (0.167 m of 0.174 m, squared 2.5° askew: the landings sweep, case
    311).  It allowed 5 cm and judged the refusal wrong; now it is the band,
    and a 0.8 m wide flight inside -- the band too where the squaring is
    twice as loose (the drift follows from equal_tolerance)."""
    cfg, rules = load_config("landings"), Rules()
    assert zone(parse_scenario(QUARTER_TURN.format(width=0.6), "x"), cfg, rules)[0] == "band"
    wide = parse_scenario(QUARTER_TURN.format(width=0.8), "x")
    assert zone(wide, cfg, rules)[0] == "inside"
    loose = replace(cfg, algorithm=msgspec.structs.replace(
        cfg.algorithm, equal_tolerance=2.0 * cfg.algorithm.equal_tolerance))
    assert zone(wide, loose, rules)[0] == "band"


@pytest.mark.parametrize(("distance", "yaw", "expected"), [
    (0.5, 0.0, "inside"), (0.95, 0.0, "inside"), (0.99, 0.0, "band"), (1.05, 0.0, "outside"),
    (0.99, 20.0, "outside"),  # both beams slant past LENGTH_OF_INFINITY (1.0 m)
    (0.8, -20.0, "inside"),
])
def test_stairs_out_of_sight_at_the_start_are_outside(distance: float, yaw: float,
                                                      expected: str) -> None:
    """The seed's calibration case 1 stops a robot whose front beams both read
    LENGTH_OF_INFINITY or more: such stairs must be refused, however easy.
    Level rays (the ideal robot): in sight up to LENGTH_OF_INFINITY exactly."""
    cfg, rules = load_config("ideal"), Rules()
    scen = parse_scenario("[stairs]\ncount = 2\nrise = 0.15\ntread = 0.3\n"
                          f"[start]\ndistance = {distance}\nyaw_deg = {yaw}\n", "x")
    assert zone(scen, cfg, rules)[0] == expected


BAD = {
    "unknown axis": ('"stairs.colour" = ["red"]', "axes.stairs.colour", "unknown axis"),
    "empty range": ('"stairs.rise" = { range = [0.2, 0.1, 0.01] }', "axes.stairs.rise.range",
                    "empty range"),
    "zero step": ('"stairs.rise" = { range = [0.1, 0.2, 0] }', "axes.stairs.rise.range",
                  "empty range"),
    "empty list": ('"stairs.rise" = []', "axes.stairs.rise", "empty list"),
    "negative count": ('"stairs.count" = [-1]', "axes.stairs.count", ">= 0"),
    "noise below 0": ('"sensors.noise" = { uniform = [-0.01, 0.01] }', "axes.sensors.noise",
                      ">= 0"),
    "config out of bounds": ('"config.masses.wheel" = { uniform = [-0.1, 0.1] }',
                             "axes.config.masses.wheel", "robot config refuses"),
    "config consistency": ('"config.algorithm.approach_gap" = { uniform = [0.0, 0.2] }',
                           "axes.config.algorithm.approach_gap", "SAFE_DISTANCE"),
    "normal reaches 0": ('"start.distance" = { normal = [0.2, 0.1] }', "axes.start.distance",
                         "> 0"),
    "unknown distribution": ('"stairs.rise" = { unifrom = [0.1, 0.2] }', "axes.stairs.rise",
                             "not an axis"),
    "fault index missing": ('"faults[0].at" = [1.0]', "axes.faults[0].at", "base has 0"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_axis_exits_2_with_one_line_before_any_work(
        case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    line, field, words = BAD[case]
    spec = tmp_path / "bad.toml"
    spec.write_text(f"[axes]\n{line}\n", encoding="utf-8")
    out = tmp_path / "out"
    assert main(["sweep", str(spec), "--out", str(out), "-j", "1"]) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(f"stairbot: error: {spec}: {field}: "), lines[0]
    assert words in lines[0], lines[0]
    assert not out.exists()  # nothing started


@pytest.mark.parametrize(("text", "field"), [
    ("[sweep]\ncases = -3\n", "sweep.cases"),
    ("[sweep]\ncases = 0\n", "sweep.cases"),
    ("[sweep]\nscenario = 'nope'\n", "sweep.scenario"),
    ("[sweep]\nseed = 'x'\n", "sweep.seed"),
    ("[report]\nx = 'stairs.rise'\n", "report.x"),
    ("[verdict]\nhome_m = 0\n", "verdict.home_m"),
    ("[axes\n", None),
])
def test_bad_spec_fields_exit_2_with_one_line(text: str, field: str | None, tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "bad.toml"
    spec.write_text(text, encoding="utf-8")
    assert main(["sweep", "check", str(spec)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"stairbot: error: {spec}: "), err
    if field:
        assert f": {field}: " in err[0], err[0]


def test_missing_dask_names_the_extra(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                      capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setitem(sys.modules, "distributed", None)  # import fails
    spec = tmp_path / "s.toml"
    spec.write_text("[axes]\n\"stairs.count\" = 1\n", encoding="utf-8")
    assert main(["sweep", str(spec), "--dask", "local", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["stairbot: error: --dask: needs the optional extra: "
                   "pip install 'stairbot[dask]'"]


def test_dask_local_listens_on_loopback_only(monkeypatch: pytest.MonkeyPatch) -> None:
    """--dask local's scheduler and workers: on 127.0.0.1, no dashboard (a
    stand-in for Dask records what the cluster is asked for; nothing starts)."""
    asked: dict[str, object] = {}

    class Cluster:
        def __init__(self, **kwargs: object) -> None:
            asked.update(kwargs)

        def close(self) -> None:
            pass

    class Client:
        def __init__(self, cluster: Cluster) -> None:
            pass

        def get_executor(self, pure: bool) -> None:
            return None

        def close(self) -> None:
            pass

    fake = types.ModuleType("distributed")
    fake.LocalCluster, fake.Client = Cluster, Client  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "distributed", fake)
    with open_executor(2, "local"):
        pass
    assert asked["host"] == "127.0.0.1" and asked["dashboard_address"] is None


def test_shipped_specs_are_valid_and_quick_stays_small() -> None:
    root = Path(__file__).parents[2] / "stairbot" / "inputs" / "sweeps"
    built = {}
    for path in sorted(root.glob("*.toml")):
        spec = parse_spec(path.read_text("utf-8"), str(path), root)
        built[spec.name] = check_spec(spec)
    assert len(built["quick"]) <= 60 and len(built["envelope"]) >= 2000
    assert {"quick", "envelope", "limits", "sensors"} <= set(built)
    assert {c.facts["zone"] for c in built["quick"]} == {"inside", "band", "outside"}


def test_a_cone_that_looks_up_sees_the_first_riser_nearer_than_a_level_ray() -> None:
    """In sight is what the simulated beams read at the start pose: 0.95 m
    from a 0.15 m riser, a VL53L1X cone tilted 7.5 deg up takes in the risers
    beyond and reads past LENGTH_OF_INFINITY; the ideal robot's level ray
    does not, nor does the reference robot's row of zones (level to 5.6 deg
    up)."""
    rules = Rules()
    scen = parse_scenario("[stairs]\ncount = 4\nrise = 0.15\ntread = 0.3\n"
                          "[start]\ndistance = 0.95\n", "x")
    assert first_sight(scen, load_config("ideal")) == pytest.approx(0.95, abs=0.002)
    assert first_sight(scen, VL53L1X_FRONT) > 1.0
    assert first_sight(scen, load_config("reference")) == pytest.approx(0.95, abs=0.005)
    assert zone(scen, load_config("ideal"), rules)[0] == "inside"
    assert zone(scen, VL53L1X_FRONT, rules)[0] == "outside"


OPEN_STAIRS = "[stairs]\ncount = 3\nrise = 0.17\ntread = 0.28\n[start]\ndistance = {}\n" \
    "yaw_deg = {}\nlateral = {}\n"


@pytest.mark.parametrize("robot", ["reference", "sonar", "ideal"])
@pytest.mark.parametrize("stairs", [OPEN_STAIRS.format(0.3, 0.0, 0.0),
                                    OPEN_STAIRS.format(0.62, -17.0, 0.12),
                                    OPEN_STAIRS.format(0.95, 9.5, -0.15),
                                    "grazed nosing"])
def test_first_sight_from_the_pose_at_rest_on_open_floor_reads_as_standing_there(
        robot: str, stairs: str) -> None:
    """first_sight moves the robot's pose at rest on open floor to where the
    case sets it down instead of stepping the physics: what the front pair
    then reads is what it reads after standing REST_S there (on the grazed
    nosing below, the half millimetre it rises to rest moves the reference
    robot's reading from riser 1 to the riser beyond)."""
    from stairbot.fakes.sim import SimRobot

    config = load_config(robot)
    scen = parse_scenario(GRAZED_NOSING if stairs == "grazed nosing" else stairs, "x")
    stood = SimRobot(config, scen)
    stood.advance(REST_S)
    hi = config.sensors.range(back=False)[1]
    seen = min([d for d in stood.board.front_seen() if d is not None and d <= hi],
               default=math.inf)
    assert first_sight(scen, config) == pytest.approx(seen, abs=1e-9)


# envelope case 485 on 52f0446: 0.945 m from a 0.122 m riser, 15 deg askew
GRAZED_NOSING = """
[stairs]
top = "landing"
steps = [{rise = 0.122146, tread = 0.345486}, {rise = 0.116755, tread = 0.354382},
         {rise = 0.118321, tread = 0.345729}, {rise = 0.117499, tread = 0.34501},
         {rise = 0.122326, tread = 0.347496}]
[start]
distance = 0.94534
yaw_deg = 15.101871
lateral = -0.001424
[sensors]
noise = 0.001
seed = 485316
"""


def test_sight_is_read_as_the_robot_stands_when_its_calibration_reads_the_pair() -> None:
    """Set down, the simulated robot has its wheels 1 mm into the floor's
    surface and rises 0.5 mm to rest before its calibration reads the pair.
    Here the top rays of the reference robot's row of zones meet riser 1's
    nosing from the pose it was set down in (0.972 m: in sight) and pass
    over it at rest to the riser beyond (1.047 m): the robot stops at case
    1 ("nothing ahead"), and the stairs are out of sight, not inside."""
    ref = load_config("reference")
    scen = parse_scenario(GRAZED_NOSING, "x")
    assert first_sight(scen, ref) > ref.LENGTH_OF_INFINITY + sight_margin(ref)
    z = zone(scen, ref, Rules())[0]
    assert z == "outside"
    rec = run_case(Case(485, {}, GRAZED_NOSING, None, {
        "zone": z, "expected_steps": 5, "faults": 0, "home_m": 0.05}))
    assert rec["result"]["reason"].startswith("nothing ahead"), rec["why"]
    assert rec["verdict"] == "refused", rec["why"]


def test_a_measured_tread_asks_its_own_riser_to_reach_min_rise_for_it() -> None:
    """The robot takes the next riser to be as high as the one it climbs
    (ascent 3), so a tread it measures (a wall on top, not a landing) needs
    its own riser at min_rise_for(tread)."""
    cone, rules = VL53L1X_FRONT, Rules()
    text = "[stairs]\ncount = 1\nrise = 0.135\ntread = {tread}\ntop = '{top}'\n"
    long_wall = parse_scenario(text.format(tread=0.38, top="wall"), "x")
    assert 0.135 < cone.min_rise_for(0.38) - rules.rise_margin_m
    assert zone(long_wall, cone, rules)[0] == "outside"
    assert zone(parse_scenario(text.format(tread=0.38, top="landing"), "x"), cone,
                rules)[0] == "inside"


def test_the_base_scenarios_robot_runs_the_cases_unless_the_spec_names_one(
        tmp_path: Path) -> None:
    """A base scenario's ``robot`` (here a file beside the scenario) becomes the
    cases' robot config and leaves the cases' scenario; ``sweep.config`` wins."""
    (tmp_path / "scen").mkdir()
    (tmp_path / "scen" / "mine.toml").write_text('extends = "ideal"\n', encoding="utf-8")
    (tmp_path / "scen" / "base.toml").write_text('robot = "mine.toml"\n[stairs]\ncount = 2\n',
                                                 encoding="utf-8")
    spec_text = '[sweep]\nscenario = "scen/base.toml"\n[axes]\n"stairs.rise" = [0.15]\n'
    case = build_case(parse_spec(spec_text, str(tmp_path / "s.toml")), 0)
    assert case.config_text is not None and "robot" not in case.scenario_text
    assert load_config("ideal").sensors == parse_config(case.config_text, "c").sensors
    chosen = parse_spec(spec_text.replace("[axes]", 'config = "sonar"\n[axes]'),
                        str(tmp_path / "s.toml"))
    assert parse_config(build_case(chosen, 0).config_text or "", "c").sensors == \
        load_config("sonar").sensors


def test_a_field_axis_inside_a_list_axis_leaves_the_list_axis_values_alone() -> None:
    """``faults`` then ``faults[0].at``: each case's fault gets its own time,
    and the ``faults`` axis's values (recorded with every case) are not
    changed by the cases built before."""
    spec = parse_spec("[axes]\nfaults = [[{ at = 0.0, sensor = \"SFR\", kind = \"error\" }]]\n"
                      "\"faults[0].at\" = [7.0, 14.5]\n", "x.toml")
    first, second = build_case(spec, 0), build_case(spec, 1)
    assert "at = 7.0" in first.scenario_text and "at = 14.5" in second.scenario_text
    assert first.axes["faults"] == [{"at": 0.0, "sensor": "SFR", "kind": "error"}]
    assert second.axes["faults"] == first.axes["faults"]
