"""Issue 12 item 5, "it loses recordings": the console never overwrites a
recording (neither `w` twice nor `--record` to an existing file); it writes
beside it, under a name not taken, and says so."""

from __future__ import annotations

import asyncio
import json
from pathlib import Path

from pilot import SpyRobot, answer_prompt, banner, press, ready, said, spied_open, until

from stairbot.console.app import build_app
from stairbot.console.cli import check_record


def test_w_twice_to_the_same_name_keeps_the_first_recording(tmp_path: Path) -> None:
    """Finding: pressing `w` twice (start, stop, start again with the same
    name) overwrote the first recording silently."""
    first, second = tmp_path / "events.jsonl", tmp_path / "events-1.jsonl"

    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await answer_prompt(pilot, "w", str(first))
            await until(pilot, lambda: "REC" in banner(app), "recording")
            await press(pilot, "k")  # a short run: calibration only
            await until(pilot, lambda: "ENDED" in banner(app), "the calibration ends")
            await press(pilot, "w")  # stop recording
            await until(pilot, lambda: "REC" not in banner(app), "stopped recording")
            kept = first.read_text()
            assert kept
            await answer_prompt(pilot, "w", str(first))
            await until(pilot, lambda: "REC" in banner(app), "recording again")
            assert first.read_text() == kept
            assert app.engine.recorder is not None
            assert str(app.engine.recorder.path) == str(second)
            assert f"{first} exists (not overwritten): recording to {second}" in said(app)
    asyncio.run(go())
    assert json.loads(first.read_text().splitlines()[-1])["kind"] == "summary"
    assert second.exists()


def test_record_option_to_an_existing_file_writes_beside_it(tmp_path: Path) -> None:
    """Finding: `stairbot console --record FILE` truncated an existing FILE."""
    old = tmp_path / "events.jsonl"
    old.write_text("an earlier recording\n")

    async def go() -> None:
        app = build_app(speed="max", record=str(old))
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            assert app.engine.recorder is not None
            assert str(app.engine.recorder.path) == str(tmp_path / "events-1.jsonl")
            assert "exists (not overwritten)" in said(app)
    asyncio.run(go())
    assert old.read_text() == "an earlier recording\n"


def test_the_command_line_check_of_record_leaves_nothing_behind(tmp_path: Path) -> None:
    """`stairbot console --record FILE` checks FILE can be written before the
    screen opens, without creating it (the console then picks the name) and
    without touching one that exists."""
    new, old = tmp_path / "new.jsonl", tmp_path / "old.jsonl"
    old.write_text("kept\n")
    check_record(str(new))
    check_record(str(old))
    assert not new.exists() and old.read_text() == "kept\n"


def test_a_disk_that_fills_mid_run_stops_the_run_and_says_which_file(
        tmp_path: Path, disk_fills: dict[str, int]) -> None:
    """Issue 11: the console's JSON-lines recorder raised a bare OSError on a
    full disk.  Now the run ends as ``stairbot run``'s does: the robot
    stopped, the reason names the file, the lines before kept whole."""
    path = tmp_path / "rec.jsonl"
    disk_fills[path.name] = 5

    spies: list[SpyRobot] = []

    async def go() -> None:
        app = build_app(speed="max", record=str(path), open_fn=spied_open(spies))
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")  # a full run: far more than five events
            await until(pilot, lambda: not app.engine.running and "cannot write the record"
                        in " ".join([said(app), banner(app)]), "the run stops, saying why")
            assert f"{path.name}: cannot write the record: No space left on device" in \
                " ".join([said(app), banner(app)])
            (spy,) = spies
            last = [c for c in spy.calls if c[0] in ("command", "stop_all", "estop")][-1]
            assert last[0] in ("stop_all", "estop")  # the robot stopped last
            assert spy.inner.estopped  # an error: the e-stop latched, as stairbot run does
    asyncio.run(go())
    kept = path.read_text().splitlines()
    assert len(kept) == 5 and all(json.loads(k) for k in kept)
