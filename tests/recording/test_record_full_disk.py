"""An MCAP record the disk refuses, or cannot open, behaves as the JSON-lines
record does (docs/config.md, "Writes"): one line, no traceback; exit 2 for a path
that cannot be opened, exit 1 for a refused write -- during a run after
every motor is stopped, the file keeping what was written before."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from stairbot.cli import main
from stairbot.recording import topics
from stairbot.recording.read import RecordingError, read_recording

QUICK = "[stairs]\ncount = 1\n"


def one_error_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err
    assert len(lines) == 1, f"expected one line, got: {err!r}"
    assert lines[0].startswith("stairbot: error: ")
    return lines[0]


@pytest.fixture
def quick(tmp_path: Path) -> Path:
    path = tmp_path / "quick.toml"
    path.write_text(QUICK, encoding="utf-8")
    return path


@pytest.mark.parametrize("name", ["x.mcap", "x.jsonl"])
def test_a_record_path_that_cannot_be_opened(tmp_path: Path, name: str,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "no such folder" / name
    assert main(["run", "-q", "--record", str(path)]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert f"{path}: cannot write the record: No such file or directory" in line


def test_a_record_on_a_full_device_is_refused_before_the_robot_moves(
        tmp_path: Path, quick: Path, capsys: pytest.CaptureFixture[str]) -> None:
    full = tmp_path / "full.mcap"
    full.symlink_to("/dev/full")
    journal = tmp_path / "journal.jsonl"
    argv = ["run", "-q", "--scenario", str(quick), "--record", str(full),
            "--journal", str(journal)]
    assert main(argv) == 1
    line = one_error_line(capsys.readouterr().err)
    assert f"{full}: cannot write the record: No space left on device" in line
    assert not journal.exists()  # refused before the robot was opened: nothing moved




def test_the_disk_filling_mid_run_stops_the_robot(tmp_path: Path, quick: Path,
                                                  disk_fills: dict[str, int],
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    record, journal = tmp_path / "r.mcap", tmp_path / "j.jsonl"
    disk_fills[record.name] = 60  # the start takes about 10 writes, a flush about 15
    argv = ["run", "-q", "--scenario", str(quick), "--record", str(record),
            "--journal", str(journal)]
    assert main(argv) == 1
    line = one_error_line(capsys.readouterr().err)
    assert "r.mcap: cannot write the record: No space left on device" in line
    assert "the run stopped, every motor stopped" in line
    end = json.loads(journal.read_text().splitlines()[-1])
    assert end["kind"] == "end" and end["outcome"] == "error"
    assert "cannot write the record" in end["error"]
    # what was written before the disk filled stays readable
    rec = read_recording(record)
    assert not rec.complete
    assert rec.counts[topics.SENSORS] > 0
    assert rec.events and rec.events[0]["kind"] == "phase"
    assert rec.telemetry.time_s[-1] <= end["time_s"]


def test_the_disk_filling_as_the_robot_is_described_stops_before_the_journal(
        tmp_path: Path, quick: Path, disk_fills: dict[str, int],
        capsys: pytest.CaptureFixture[str]) -> None:
    record, journal = tmp_path / "r.mcap", tmp_path / "j.jsonl"
    disk_fills[record.name] = 7  # the file's start, not the scenario and scene after it
    argv = ["run", "-q", "--scenario", str(quick), "--record", str(record),
            "--journal", str(journal)]
    assert main(argv) == 1
    line = one_error_line(capsys.readouterr().err)
    assert "r.mcap: cannot write the record: No space left on device" in line
    assert "the run stopped" not in line  # it never started
    assert not journal.exists()
    with pytest.raises(RecordingError, match="holds no messages"):  # its start, no run
        read_recording(record)
