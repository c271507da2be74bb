"""``stairbot plot FILE`` (issue 12, item 4): a PNG from an MCAP or a
JSON-lines recording; bad input and a missing matplotlib are one line and
exit 2, never a traceback."""

from __future__ import annotations

import struct
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from mcap.writer import Writer

from stairbot.cli import main
from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind
from stairbot.recording.mcap_sink import McapRecord

QUICK = "[stairs]\ncount = 1\n"
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def recordings(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("plot")
    (d / "quick.toml").write_text(QUICK, encoding="utf-8")
    out = {"mcap": d / "quick.mcap", "jsonl": d / "quick.jsonl"}
    for path in out.values():
        assert main(["run", "-q", "--scenario", str(d / "quick.toml"), "--record",
                     str(path)]) == 0
    return out


def png_size(data: bytes) -> tuple[int, int]:
    assert data.startswith(PNG) and data[12:16] == b"IHDR"
    width, height = struct.unpack(">II", data[16:24])
    return width, height


def test_a_png_from_an_mcap_recording(recordings: dict[str, Path],
                                      capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plot", str(recordings["mcap"])]) == 0
    out = recordings["mcap"].with_suffix(".png")
    data = out.read_bytes()
    width, height = png_size(data)
    assert (width, height) == (1200, 1210)  # 12 x 12.1 inches at 100 dpi: six panels
    assert 50_000 < len(data) < 3_000_000
    said = capsys.readouterr().out
    assert said.startswith(f"wrote {out} (") and " ticks, " in said


def test_a_png_from_a_json_lines_record(recordings: dict[str, Path], tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "events.png"
    assert main(["plot", str(recordings["jsonl"]), "-o", str(out)]) == 0
    width, height = png_size(out.read_bytes())
    assert width == 1200 and height < 500  # the phases and the events: two panels
    assert "a record of events alone" in capsys.readouterr().out


def _foreign_mcap(path: Path) -> None:
    with path.open("wb") as f:
        writer = Writer(f)
        writer.start()
        schema = writer.register_schema(name="x", encoding="jsonschema", data=b"{}")
        channel = writer.register_channel(topic="/x", message_encoding="json", schema_id=schema)
        writer.add_message(channel, log_time=0, data=b"{}", publish_time=0)
        writer.finish()


def _cut_in_its_header(path: Path, recordings: dict[str, Path]) -> None:
    path.write_bytes(recordings["mcap"].read_bytes()[:100])  # before its metadata


def _no_messages(path: Path, recordings: dict[str, Path]) -> None:
    McapRecord(path, load_config(None)).close()  # a record closed before any run


BAD: dict[str, tuple[Any, str]] = {
    "missing": (None, "cannot read a recording: No such file or directory"),
    "directory": ("dir", "cannot read a recording: a directory"),
    "empty": (b"", "empty; allowed: an MCAP or JSON-lines recording"),
    "blank": (b"\n  \n", "empty; allowed: an MCAP or JSON-lines recording"),
    "toml": (QUICK.encode(), "line 1: not JSON; allowed: an MCAP file or JSON lines"),
    "binary": (bytes(range(256)) * 4, "line 1: not JSON"),
    "json-not-events": (b'{"a": 1}\n', "line 1: not a stairbot event"),
    "foreign-mcap": (_foreign_mcap, "an MCAP file, but not a stairbot recording"),
    "mcap-cut-in-its-header": (_cut_in_its_header, "not a stairbot recording"),
    "mcap-without-messages": (_no_messages, "a stairbot recording that holds no messages"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_is_one_line_and_exit_2(case: str, tmp_path: Path,
                                          recordings: dict[str, Path],
                                          capsys: pytest.CaptureFixture[str]) -> None:
    content, expected = BAD[case]
    path = tmp_path / f"{case}.rec"
    if content == "dir":
        path.mkdir()
    elif isinstance(content, bytes):
        path.write_bytes(content)
    elif content is _foreign_mcap:
        _foreign_mcap(path)
    elif content is not None:
        content(path, recordings)
    assert main(["plot", str(path)]) == 2
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err and len(lines) == 1, err
    assert lines[0].startswith(f"stairbot: error: {path}: ") and expected in lines[0]
    assert not path.with_suffix(".png").exists()


def test_an_output_that_cannot_be_written(recordings: dict[str, Path], tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "no such folder" / "x.png"
    assert main(["plot", str(recordings["jsonl"]), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.strip() == (f"stairbot: error: {out}: cannot write the plot: "
                           "No such file or directory")


def test_without_matplotlib_one_line_names_the_extra(recordings: dict[str, Path]) -> None:
    probe = ("import sys; sys.modules['matplotlib'] = None\n"
             "from stairbot.cli import main; sys.exit(main(sys.argv[1:]))")
    proc = subprocess.run([sys.executable, "-c", probe, "plot", str(recordings["mcap"]),
                           "-o", str(recordings["mcap"].with_suffix(".none.png"))],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr == ("stairbot: error: stairbot plot: needs matplotlib, which is not "
                           "installed: pip install 'stairbot[plot]'\n")
    assert not recordings["mcap"].with_suffix(".none.png").exists()


def test_an_mcap_recording_without_ticks_plots_its_events(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "events-only.mcap"
    record = McapRecord(path, load_config(None))
    record.write(Event(0.0, EventKind.WARNING, "emergency stop by the operator"))
    record.close()
    assert main(["plot", str(path)]) == 0
    width, height = png_size(path.with_suffix(".png").read_bytes())
    assert width == 1200 and height < 500  # the phases and the events alone
    assert "(no tick, 1 events)" in capsys.readouterr().out


def test_a_read_the_disk_fails_is_one_line_and_exit_1(
        recordings: dict[str, Path], tmp_path: Path, recording_read_fails: None,
        capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "x.png"
    assert main(["plot", str(recordings["mcap"]), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err == (f"stairbot: error: {recordings['mcap']}: cannot read the recording: "
                   "Input/output error\n")
    assert not out.exists()
