"""MCAP from the other places a run is recorded: the console (``--record
FILE.mcap``, the ``w`` key), and a robot on a wire, whose pose the host can
only estimate -- the channel says so -- and whose link has health to tell."""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from mcap.reader import make_reader

from stairbot.cli import main
from stairbot.console.engine import ConsoleEngine
from stairbot.console.state import LiveState
from stairbot.control.robot_config import load_config
from stairbot.recording import topics
from stairbot.recording.read import read_recording

QUICK = "[stairs]\ncount = 1\n"
TICK_S = load_config(None).algorithm.tick


@pytest.fixture
def quick(tmp_path: Path) -> Path:
    path = tmp_path / "quick.toml"
    path.write_text(QUICK, encoding="utf-8")
    return path


def test_the_console_records_mcap_for_a_name_ending_mcap(tmp_path: Path, quick: Path) -> None:
    engine = ConsoleEngine(LiveState(url="sim://"), load_config(None))
    engine.start_recording(str(tmp_path / "console.mcap"))  # before a robot is open, as --record
    engine.open("sim://", str(quick))
    result = engine.run("full")
    assert result is not None and result.outcome == "completed"
    engine.estop()  # from the UI thread, after the run: recorded too
    engine.stop_recording()
    engine.close()
    rec = read_recording(tmp_path / "console.mcap")
    ticks = round(result.sim_time_s / TICK_S)
    assert rec.complete
    for topic in (*topics.TICK_TOPICS, "/sim/true_pose"):
        assert rec.counts[topic] == ticks, topic
    assert rec.counts[topics.SCENE] == 1
    assert rec.events[-1]["message"] == "emergency stop by the operator"
    assert rec.counts[topics.EVENTS] == len(rec.events)
    assert rec.metadata["robot"]["url"] == "sim://"


def test_the_console_keeps_json_lines_for_other_names(tmp_path: Path, quick: Path) -> None:
    engine = ConsoleEngine(LiveState(url="sim://"), load_config(None))
    engine.open("sim://", str(quick))
    engine.start_recording(str(tmp_path / "events.jsonl"))
    engine.estop()
    engine.stop_recording()
    engine.close()
    assert (tmp_path / "events.jsonl").read_text().count("emergency stop by the operator") == 1
    assert read_recording(tmp_path / "events.jsonl").kind == "jsonl"


@pytest.fixture
def fake_boards_url(tmp_path: Path, quick: Path) -> Iterator[str]:
    proc = subprocess.Popen([sys.executable, "-m", "stairbot", "fake-boards", "--serial",
                             "--lockstep", "--scenario", str(quick)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    assert proc.stdout is not None
    url = proc.stdout.readline().strip()
    try:
        assert url.startswith("serial:///dev/"), url
        yield url
    finally:
        proc.terminate()
        proc.communicate(timeout=10)


def test_a_robot_on_a_wire_records_an_estimated_pose_and_its_link(
        tmp_path: Path, quick: Path, fake_boards_url: str) -> None:
    record = tmp_path / "wire.mcap"
    assert main(["run", "-q", "--robot", fake_boards_url + "&timeout=2", "--scenario",
                 str(quick), "--record", str(record), "--journal",
                 str(tmp_path / "journal.jsonl")]) == 0
    rec = read_recording(record)
    summary = rec.events[-1]
    ticks = round(summary["data"]["sim_time_s"] / TICK_S)
    assert rec.counts["/robot/estimated_pose"] == ticks
    assert "/sim/true_pose" not in rec.counts  # the host is not given the simulation
    assert rec.telemetry.pose_topic == "/robot/estimated_pose"
    assert "dead-reckoned" in rec.metadata["robot"]["pose"]
    # the estimate climbs the step and comes back, as the counters say
    heights = rec.telemetry.height_m["segment2"]
    assert max(heights) == pytest.approx(0.016 + 0.17, abs=0.02)
    assert heights[-1] == pytest.approx(heights[0], abs=0.01)
    assert rec.counts[topics.LINK] == ticks
    with record.open("rb") as f:
        links = [json.loads(m.data) for _s, _c, m in
                 make_reader(f).iter_messages(topics=[topics.LINK])]
    assert links[-1]["health"]["frames_tx"] > links[0]["health"]["frames_tx"] > 0
    assert links[-1]["health"]["lost"] == 0
