"""A disk that fills mid-sweep: one line naming the file, exit 1, the cases
written before kept whole, and ``--resume`` finishes once there is room."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from stairbot.cli import main

SPEC = """
[sweep]
name = "fills"
cases = 6
seed = 5
[axes]
"stairs.count" = 1
"sensors.seed" = { randint = [1, 1000000] }
"""


def test_a_full_disk_stops_the_sweep_and_resume_finishes_it(
        tmp_path: Path, disk_fills: dict[str, int],
        capsys: pytest.CaptureFixture[str]) -> None:
    spec, out = tmp_path / "fills.toml", tmp_path / "out"
    spec.write_text(SPEC, encoding="utf-8")
    disk_fills["cases.jsonl"] = 3  # the disk fills after three case lines
    argv = ["sweep", str(spec), "-j", "1", "--out", str(out), "-q", "--no-png"]
    assert main(argv) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert "cases.jsonl: cannot write the sweep results: No space left on device" in err[0]
    assert "3 finished case(s) kept" in err[0] and "--resume" in err[0]
    kept = [json.loads(x) for x in (out / "cases.jsonl").read_text("utf-8").splitlines()]
    assert len(kept) == 3

    del disk_fills["cases.jsonl"]  # room again
    assert main([*argv, "--resume"]) == 0
    cases = sorted(json.loads(x)["case"]
                   for x in (out / "cases.jsonl").read_text("utf-8").splitlines())
    assert cases == list(range(6))  # each exactly once


def test_a_results_file_that_is_not_a_regular_file_is_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec, out = tmp_path / "fills.toml", tmp_path / "out"
    spec.write_text(SPEC, encoding="utf-8")
    out.mkdir()
    os.mkfifo(out / "cases.jsonl")  # read as results it would hang
    assert main(["sweep", str(spec), "--out", str(out), "-q", "--no-png", "--resume"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err and "cases.jsonl" in err[-1] and "not a regular file" in err[-1]
