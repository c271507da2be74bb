"""Names and paths with control characters (ANSI and OSC escape sequences, a
BEL, a carriage return, C1 controls, a bidirectional override): a name field
holding one is refused at load with one line naming the file and the field;
a path, a name taken from a file name, or text from a results folder is
printed with its control characters escaped, never raw."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from stairbot.cli import main
from stairbot.text import printable

OSC_TITLE = "\x1b]0;pwned\x07"  # sets the terminal's title
CSI_CLEAR = "\x1b[2J"  # clears the screen
HOSTILE = OSC_TITLE + CSI_CLEAR + "\x9b31m" + "\r" + "\u202e" + "\x7f"
RAW = ("\x1b", "\x07", "\x9b", "\r", "\u202e", "\x7f")


def clean(text: str) -> None:
    """No raw control character reaches the terminal (newlines between lines aside)."""
    for ch in RAW:
        assert ch not in text, f"{ch!r} printed raw in {text!r}"


def test_printable_escapes_control_characters_and_nothing_else() -> None:
    assert printable(HOSTILE) == ("\\x1b]0;pwned\\x07\\x1b[2J\\x9b31m\\x0d\\u202e\\x7f")
    assert printable("one\ntwo\tthree") == "one\\x0atwo\\x09three"
    assert printable("Tür 中 ✓ stairs.rise [0.1]") == "Tür 中 ✓ stairs.rise [0.1]"
    assert printable(printable(HOSTILE)) == printable(HOSTILE)


@pytest.mark.parametrize("field", ["name", "description"])
def test_a_scenario_name_with_control_characters_is_refused_at_load(
        field: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "s.toml"
    path.write_text(f"{field} = {json.dumps('stairs' + HOSTILE)}\n", encoding="utf-8")
    assert main(["scenario", "check", str(path)]) == 2
    assert main(["run", "--scenario", str(path)]) == 2
    out, err = capsys.readouterr()
    clean(out + err)
    line = (f"stairbot: error: {path}: {field}: holds the control character \\x1b at "
            "character 6; allowed: printable text on one line (no control characters or "
            "escape sequences)")
    assert err.splitlines() == [line, line] and out == ""


@pytest.mark.parametrize("field", ["name", "description"])
def test_a_sweep_name_with_control_characters_is_refused_at_load(
        field: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "spec.toml"
    path.write_text(f"[sweep]\n{field} = {json.dumps(OSC_TITLE)}\n", encoding="utf-8")
    assert main(["sweep", "check", str(path)]) == 2
    out, err = capsys.readouterr()
    clean(out + err)
    assert err.splitlines() == [
        f"stairbot: error: {path}: sweep.{field}: holds the control character \\x1b at "
        "character 0; allowed: printable text on one line (no control characters or "
        "escape sequences)"]


def test_a_sweep_name_with_a_slash_is_refused(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "spec.toml"
    path.write_text('[sweep]\nname = "../elsewhere"\n', encoding="utf-8")
    assert main(["sweep", "check", str(path)]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"stairbot: error: {path}: sweep.name: '../elsewhere' names the results folder; "
        "allowed: a name without / or \\"]


def test_a_file_name_with_escape_sequences_is_printed_escaped(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / f"stairs{HOSTILE}.toml"
    path.write_text("[stairs]\ncount = 1\n", encoding="utf-8")  # its name: the file's stem
    assert main(["scenario", "check", str(path)]) == 0
    assert main(["run", "--scenario", str(path)]) == 0  # progress lines, then the summary
    spec = tmp_path / f"sweep{HOSTILE}.toml"
    spec.write_text("", encoding="utf-8")
    assert main(["sweep", "check", str(spec)]) == 0
    out, err = capsys.readouterr()
    clean(out + err)
    assert f"ok  {printable(path)}: 1 steps" in out
    assert f"running stairs{printable(HOSTILE)} on sim://" in out
    assert f"summary (stairs{printable(HOSTILE)} on sim://)" in out
    assert f"ok  {printable(spec)}: 1 case(s)" in out


def test_an_error_naming_a_hostile_path_is_one_escaped_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / f"no{HOSTILE}.toml"
    assert main(["run", "--scenario", str(missing)]) == 2
    assert main(["sweep", "check", str(missing)]) == 2
    out, err = capsys.readouterr()
    clean(out + err)
    lines = err.splitlines()
    assert len(lines) == 2 and all(printable(missing) in line for line in lines), lines


def test_sweep_report_prints_a_results_folder_s_text_escaped(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A results folder is read back as written, from wherever it came: its
    name, axis values and reasons are printed escaped, brackets as brackets."""
    folder = tmp_path / "results"
    folder.mkdir()
    (folder / "sweep.json").write_text(json.dumps(
        {"name": f"evil{HOSTILE}[/]", "total": 1, "axes": [],
         "report": {"worst": 5, "bins": 12}}), encoding="utf-8")
    record = {"case": 0, "axes": {"stairs.top": f"wall{CSI_CLEAR}"}, "verdict": "unsafe",
              "why": f"fell {OSC_TITLE}[bold]x[/]", "result": {"max_pitch_deg": 40.0},
              "facts": {"max_rise_m": 0.17, "min_tread_m": 0.28}, "reproduce": "r.toml"}
    (folder / "cases.jsonl").write_text(json.dumps(record) + "\n", encoding="utf-8")
    assert main(["sweep", "report", str(folder), "--no-png"]) == 1
    out, err = capsys.readouterr()
    clean(out + err)
    assert "evil\\x1b]0;pwned\\x07" in out and "[/]" in out
    assert "[bold]x[/]" in out and "wall\\x1b[2J" in out
