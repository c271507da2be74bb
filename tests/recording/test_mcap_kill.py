"""A run recording MCAP, killed with SIGKILL part way (issue 12, item 1):
the file it leaves is read up to where it ends, and holds every tick up to
the last flush before the kill.

No timing assumption: the bound comes from what the process had said
before it was killed.  It prints a line at each phase change, at the robot
time of that tick; by then every earlier tick was recorded, and the writer
leaves at most FLUSH_TICKS - 1 of them unflushed (it flushes on the wall
clock as well, which only leaves fewer)."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from stairbot.control.robot_config import load_config
from stairbot.recording import topics
from stairbot.recording.mcap_sink import FLUSH_TICKS
from stairbot.recording.plot import render
from stairbot.recording.read import read_recording

TICK_S = load_config(None).algorithm.tick
KILL_AFTER_S = 120.0  # robot seconds: 6000 ticks, of which FLUSH_TICKS is 4 %
LINE = re.compile(r"^\[\s*([0-9.]+) s\] (\w+)\s+(.*)$")


def _run_until(path: Path, robot_s: float) -> list[tuple[float, str, str]]:
    """Start a paced default run recording to ``path``; SIGKILL it as soon as
    it prints a progress line at ``robot_s`` or later; the lines it printed."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "stairbot", "run", "--realtime", "--time-scale", "50",
         "--record", str(path)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    # a run that hangs must not hang the test: kill it after 5 minutes whatever it said
    guard = threading.Timer(300, proc.kill)
    guard.start()
    lines: list[tuple[float, str, str]] = []
    try:
        assert proc.stdout is not None
        for raw in proc.stdout:
            m = LINE.match(raw.rstrip("\n"))
            if m is None:
                continue
            lines.append((float(m[1]), m[2], m[3]))
            if lines[-1][0] >= robot_s:
                os.kill(proc.pid, signal.SIGKILL)
                break
    finally:
        guard.cancel()
        proc.kill()
        proc.wait()
    assert proc.returncode == -signal.SIGKILL, "the run ended before it was killed"
    return lines


def test_a_killed_run_keeps_all_but_the_last_flush(tmp_path: Path) -> None:
    path = tmp_path / "killed.mcap"
    lines = _run_until(path, KILL_AFTER_S)
    last_said = lines[-1][0]
    said_ticks = round(last_said / TICK_S)  # ticks recorded before that line was printed

    rec = read_recording(path)
    assert not rec.complete  # no summary, no footer: cut short
    for topic in (*topics.TICK_TOPICS, "/sim/true_pose"):
        kept = rec.counts[topic]
        assert kept >= said_ticks - (FLUSH_TICKS - 1), (topic, kept, said_ticks)
        assert kept >= 0.95 * said_ticks
    # the ticks kept are the first ones, in order, a tick apart
    times = rec.telemetry.time_s
    assert times[0] == 0.0
    assert times[-1] == pytest.approx((len(times) - 1) * TICK_S, abs=1e-5)
    # every event printed up to the last flush is there too; none after the last tick kept
    flushed_s = (said_ticks - FLUSH_TICKS) * TICK_S
    kept_events = [(e["time_s"], e["message"]) for e in rec.events]
    said = [(t, msg) for t, _kind, msg in lines if t <= flushed_s]
    assert said and set(said) <= set(kept_events)
    assert max(t for t, _ in kept_events) <= times[-1] + TICK_S + 1e-6
    assert rec.attachments.keys() == set(topics.ATTACHMENTS)
    # and it can be plotted
    assert render(rec).startswith(b"\x89PNG\r\n\x1a\n")
