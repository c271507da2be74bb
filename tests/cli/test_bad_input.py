"""Bad input exits 2 with one line naming the file, the field and what is
allowed, never a traceback: through main(argv) and through the installed
console script."""

from __future__ import annotations

import shutil
import subprocess
import sys
from importlib import resources
from pathlib import Path

import pytest

from stairbot.cli import main

ROBOT = resources.files("stairbot.inputs").joinpath("default_robot.toml").read_text("utf-8")


def write(tmp_path: Path, name: str, text: str) -> str:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return str(p)


def one_error_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, f"expected one line, got: {err!r}"
    assert lines[0].startswith("stairbot: error: ")
    assert "Traceback" not in err
    return lines[0]


CASES = [
    # (file name, text, option, words the one line must contain)
    ("bad_key.toml", "[stairs]\ncolour = 'red'\n", "--scenario",
     ["bad_key.toml", "stairs.colour", "unknown key", "count, rise, tread"]),
    ("wrong_type.toml", "[start]\nyaw_deg = 'left'\n", "--scenario",
     ["wrong_type.toml", "start.yaw_deg", "'left'", "a number >= -80 and <= 80"]),
    ("negative.toml", "[stairs]\nrise = -0.17\n", "--scenario",
     ["negative.toml", "stairs.rise", "-0.17", ">= 0.005 and <= 1"]),
    ("not_toml.toml", "[stairs\nrise = \n", "--scenario", ["not_toml.toml", "not valid TOML"]),
    ("robot_long.toml",
     ROBOT.replace("[geometry]\n", "[geometry]\nLENGTH_OF_A_ROBOT = 0.3\n"), "--config",
     ["robot_long.toml", "geometry.LENGTH_OF_A_ROBOT", "add up to 0.2250"]),
    ("robot_neg.toml", ROBOT.replace("wheel_radius = 0.016", "wheel_radius = -0.016"),
     "--config", ["robot_neg.toml", "geometry.wheel_radius", ">= 0.001"]),
    ("robot_key.toml", ROBOT.replace("[masses]\n", "[masses]\nbattery = 2\n"), "--config",
     ["robot_key.toml", "masses.battery", "unknown key"]),
    ("robot_section.toml", ROBOT + "\n[battery]\nvolts = 12\n", "--config",
     ["robot_section.toml", "battery", "unknown key", "geometry, masses, motors"]),
    ("robot_inf.toml", ROBOT.replace("lift_travel = 0.21", "lift_travel = inf"), "--config",
     ["robot_inf.toml", "motors.lift_travel", "inf is not allowed",
                       ">= 0.001 and <= 10, finite"]),
    ("robot_bool.toml", ROBOT.replace("max_steps = 10", "max_steps = true"), "--config",
     ["robot_bool.toml", "algorithm.max_steps", "true is not allowed", "a whole number"]),
    ("robot_tick.toml", ROBOT.replace("tick = 0.02", "tick = 0.0005"), "--config",
     ["robot_tick.toml", "algorithm.tick", "0.0005", ">= 0.001 and <= 0.5"]),
    ("robot_empty.toml", "", "--config",
     ["robot_empty.toml", "geometry", "required but missing"]),
    ("empty_steps.toml", "[stairs]\nsteps = [{rise = 0.17}]\n", "--scenario",
     ["empty_steps.toml", "stairs.steps[0].tread", "required but missing",
                           ">= 0.01 and <= 10"]),
    ("fault_sensor.toml", "[[faults]]\nat = 1.0\nsensor = 'SXX'\nkind = 'error'\n",
     "--scenario", ["fault_sensor.toml", "faults[0].sensor", "'SFR'", "'SBL'"]),
    ("fault_key.toml", "[[faults]]\nat = 1.0\nsensor = 'SFL'\nkind = 'error'\nwhen = 2\n",
     "--scenario", ["fault_key.toml", "faults[0].when", "unknown key", "duration"]),
    ("fault_nan.toml",
     "[[faults]]\nat = 1.0\nsensor = 'SFL'\nkind = 'offset'\noffset = nan\n",
     "--scenario", ["fault_nan.toml", "faults[0].offset", "nan is not allowed", "finite"]),
    ("error_offset.toml",
     "[[faults]]\nat = 1.0\nsensor = 'SFL'\nkind = 'error'\noffset = 0.05\n",
     "--scenario", ["error_offset.toml", "faults[0].offset", "only an 'offset' fault"]),
    ("lateral_inf.toml", "[start]\nlateral = -inf\n", "--scenario",
     ["lateral_inf.toml", "start.lateral", "-inf is not allowed"]),
    ("yaw.toml", "[start]\nyaw_deg = 95.0\n", "--scenario",
     ["yaw.toml", "start.yaw_deg", "95.0", ">= -80 and <= 80"]),
    ("far.toml", "[start]\ndistance = 50.0\n", "--scenario",
     ["far.toml", "start.distance", "<= 20"]),
    ("expect.toml", "[expect]\noutcome = 'great'\n", "--scenario",
     ["expect.toml", "expect.outcome", "'great'", "'completed'"]),
    ("top_key.toml", "colour = 'red'\n", "--scenario",
     ["top_key.toml", "colour", "unknown key", "stairs, start, sensors"]),
    ("robot_name.toml", "robot = 'spider'\n", "--scenario",
     ["robot_name.toml: robot", "'spider'", "neither a shipped robot nor a file",
      "landings", "robot config file's path"]),
    ("robot_path.toml", "robot = 'robots/none.toml'\n", "--scenario",
     ["robot_path.toml: robot", "no such file", "none.toml", "a shipped robot's name"]),
    ("robot_type.toml", "robot = 3\n", "--scenario", ["robot_type.toml: robot", "text"]),
]


@pytest.mark.parametrize(("name", "text", "option", "words"), CASES,
                         ids=[c[0] for c in CASES])
def test_run_with_a_bad_file_exits_2_with_one_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str],
        name: str, text: str, option: str, words: list[str]) -> None:
    path = write(tmp_path, name, text)
    assert main(["run", option, path]) == 2
    out, err = capsys.readouterr()
    line = one_error_line(err)
    for w in words:
        assert w in line
    assert out == ""


def test_config_show_with_a_bad_file_exits_2(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write(tmp_path, "r.toml", ROBOT.replace("lift_speed = 10.0", "lift_speed = 0"))
    assert main(["config", "show", "--config", path]) == 2
    assert "motors.lift_speed" in one_error_line(capsys.readouterr().err)


@pytest.mark.parametrize("option", ["--scenario", "--config"])
def test_a_missing_file_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                option: str) -> None:
    missing = str(tmp_path / "nowhere.toml")
    assert main(["run", option, missing]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert missing in line and "cannot read" in line


def test_an_unknown_scenario_name_lists_the_shipped_ones(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "--scenario", "spiral_staircase"]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert "spiral_staircase" in line and "wall_at_top" in line


@pytest.mark.parametrize(("url", "words"), [
    ("warp://drive", ["warp://drive", "unknown scheme 'warp'", "sim://"]),
    ("robot", ["not a robot URL", "sim://"]),
    ("sim://elsewhere", ["sim://elsewhere", "allowed: sim://"]),
])
def test_a_bad_robot_url_exits_2(capsys: pytest.CaptureFixture[str], url: str,
                                 words: list[str]) -> None:
    assert main(["run", "--robot", url]) == 2
    line = one_error_line(capsys.readouterr().err)
    for w in words:
        assert w in line


def test_an_unwritable_record_file_exits_2(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    target = str(tmp_path / "no" / "such" / "dir" / "run.jsonl")
    assert main(["run", "--record", target]) == 2
    assert "cannot write the record" in one_error_line(capsys.readouterr().err)


def test_scenario_check_reports_each_bad_file(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    good = write(tmp_path, "good.toml", "[stairs]\ncount = 2\n")
    bad = write(tmp_path, "bad.toml", "[start]\ndistance = -1\n")
    assert main(["scenario", "check", good, bad]) == 2
    out, err = capsys.readouterr()
    assert "ok  " in out and "good.toml" in out
    assert "bad.toml: start.distance" in one_error_line(err)
    assert main(["scenario", "check", good, "default"]) == 0


def test_an_unknown_option_is_an_argparse_error_exit_2(
        capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(["run", "--fast"])
    assert info.value.code == 2
    assert "unrecognized arguments: --fast" in capsys.readouterr().err


def console_script() -> list[str]:
    exe = shutil.which("stairbot", path=str(Path(sys.executable).parent))
    return [exe] if exe else [sys.executable, "-m", "stairbot"]


def test_the_installed_script_prints_no_traceback_for_bad_input(tmp_path: Path) -> None:
    path = write(tmp_path, "s.toml", "[[faults]]\nat = 1\nsensor = 'SFQ'\nkind = 'error'\n")
    proc = subprocess.run([*console_script(), "run", "--scenario", path],
                          capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert proc.returncode == 2
    line = one_error_line(proc.stderr)
    assert "faults[0].sensor" in line and "'SFQ'" in line and "'SFL'" in line
    assert proc.stdout == ""


@pytest.mark.parametrize("option", ["--scenario", "--config"])
def test_a_binary_file_or_a_directory_exits_2(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str],
                                              option: str) -> None:
    binary = tmp_path / "blob.toml"
    binary.write_bytes(b"\x7fELF\x02\x01\x01\x00\xff\xfe\x00\x00")
    assert main(["run", option, str(binary)]) == 2
    assert "blob.toml: not a UTF-8 text file" in one_error_line(capsys.readouterr().err)
    folder = tmp_path / "folder.toml"
    folder.mkdir()
    assert main(["run", option, str(folder)]) == 2
    assert "folder.toml: cannot read" in one_error_line(capsys.readouterr().err)


@pytest.mark.parametrize(("argv", "words"), [
    (["run", "--from-top", "--calibrate-only", "--scenario", "top_descent"],
     ["--calibrate-only", "top of a flight"]),
    (["run", "--calibrate-only", "--scenario", "top_descent"],
     ["--calibrate-only", "top of a flight"]),
    (["run", "--from-top"], ["--from-top", "start.on = 'top'"]),
])
def test_from_the_top_with_what_cannot_go_with_it_exits_2(
        argv: list[str], words: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    assert main(argv) == 2
    line = one_error_line(capsys.readouterr().err)
    for w in words:
        assert w in line, line
