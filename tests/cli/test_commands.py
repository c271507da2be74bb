"""`stairbot --help`, `config show`, `scenario list/check`, and the lazily
dispatched subcommands."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from stairbot.cli.command import EXTERNAL, main
from stairbot.inputs.scenario import shipped_scenarios


@pytest.mark.parametrize("argv", [[], ["run"], ["config"], ["config", "show"], ["scenario"],
                                  ["scenario", "check"], ["scenario", "list"]])
def test_every_subcommand_has_help(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main([*argv, "--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: stairbot")
    assert len(out.splitlines()) > 3


def test_top_level_help_lists_every_command(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["--help"])
    out = capsys.readouterr().out
    for name in ("run", "config", "scenario", *EXTERNAL):
        assert f"    {name}" in out


def test_no_command_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main([])
    assert info.value.code == 2
    assert "required: COMMAND" in capsys.readouterr().err


def test_config_show_text_has_every_section_and_the_derived_values(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["config", "show"]) == 0
    out = capsys.readouterr().out
    for section in ("[geometry]", "[masses]", "[motors]", "[sensors]", "[algorithm]",
                    "[safety]", "[derived]"):
        assert section in out
    assert "SAFE_DISTANCE_IN_FRONT_OF_STEP = 0.1" in out
    derived = out[out.index("[derived]"):]
    assert any(line.startswith("max_step_rise_m") and "0.202" in line
               for line in derived.splitlines())
    assert any(line.startswith("min_tread_m") and "0.26" in line
               for line in derived.splitlines())
    assert any(line.startswith("MAX_OF_VERTICAL_TURNS") and "105" in line and "turns" in line
               for line in derived.splitlines())


SEED_CONSTANTS = (
    "SAFE_DISTANCE_IN_FRONT_OF_STEP", "SAFE_LENGTH", "MAX_OF_VERTICAL_TURNS",
    "NUMBER_OF_VERTICAL_TURNS_FOR_CLEARANCE", "NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH",
    "NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE", "NUMBER_OF_HORIZONTAL_TURNS_FOR_SECOND_MODULE",
    "LENGTH_OF_A_ROBOT", "LENGTH_OF_FIRST_MODULE", "LENGTH_OF_SECOND_MODULE",
    "LENGTH_OF_THIRD_MODULE", "LENGTH_OF_INFINITY", "BACK_CLEARANCE",
)


def test_config_show_prints_every_seed_constant_under_its_seed_name(
        capsys: pytest.CaptureFixture[str]) -> None:
    # the constant table of ../shared/ALGORITHM.md, each with a value on its own line
    assert main(["config", "show"]) == 0
    lines = capsys.readouterr().out.splitlines()
    for name in SEED_CONSTANTS:
        assert any(line.split("=")[0].strip() == name and "=" in line for line in lines), name
    assert main(["config", "show", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    flat = {k for section in data.values() if isinstance(section, dict) for k in section}
    assert set(SEED_CONSTANTS) <= flat


def test_config_show_json_is_the_resolved_config(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["config", "show", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["derived"]["max_step_rise_m"] == pytest.approx(0.202)
    assert data["derived"]["min_tread_m"] == pytest.approx(0.26)
    assert data["geometry"]["LENGTH_OF_A_ROBOT"] == pytest.approx(0.225)
    assert data["algorithm"]["max_steps"] == 10


def test_scenario_list_names_every_shipped_scenario(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scenario", "list"]) == 0
    out = capsys.readouterr().out
    assert [line.split()[0] for line in out.splitlines()] == shipped_scenarios()


def test_scenario_check_accepts_every_shipped_scenario(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scenario", "check", *shipped_scenarios()]) == 0
    assert capsys.readouterr().out.count("ok  ") == len(shipped_scenarios())


def test_python_dash_m_stairbot_is_the_same_command(tmp_path: Path) -> None:
    # cwd elsewhere: the installed package runs, not a source tree that happens to be here
    proc = subprocess.run([sys.executable, "-m", "stairbot", "config", "show", "--json"],
                          capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert proc.returncode == 0
    assert "max_step_rise_m" in json.loads(proc.stdout)["derived"]


def test_an_external_command_that_is_missing_says_so(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setitem(EXTERNAL, "console", ("stairbot.no_such_module:main", "gone"))
    assert main(["console"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("stairbot: error: `stairbot console` is not available")


def test_external_commands_get_their_own_arguments(
        monkeypatch: pytest.MonkeyPatch) -> None:
    seen: list[list[str]] = []

    def fake_main(argv: list[str]) -> int:
        seen.append(argv)
        return 7

    import types
    module = types.ModuleType("stairbot_fake_external")
    setattr(module, "main", fake_main)  # noqa: B010 - a module built for the test
    monkeypatch.setitem(sys.modules, "stairbot_fake_external", module)
    monkeypatch.setitem(EXTERNAL, "console", ("stairbot_fake_external:main", "fake"))
    assert main(["console", "--robot", "sim://", "--help"]) == 7
    assert seen == [["--robot", "sim://", "--help"]]


def test_python_dash_m_stairbot_from_the_checkout_root_has_every_subpackage() -> None:
    root = Path(__file__).resolve().parents[2]
    if not (root / "stairbot" / "__main__.py").is_file():
        pytest.skip("not run from a source checkout")
    # cwd = the checkout: Python finds ./stairbot (the whole package) first
    for command in (["fake-boards", "--help"], ["console", "--help"]):
        proc = subprocess.run([sys.executable, "-m", "stairbot", *command],
                              capture_output=True, text=True, timeout=60, cwd=root)
        assert proc.returncode == 0, proc.stderr
        assert proc.stdout.startswith(f"usage: stairbot {command[0]}")
