"""What the run journal costs a tick: the time ``JournalWriter.tick`` takes
the control loop, with and without fsync, and the bytes it writes, over the
ticks of a real default run (its phases, commands and contexts, replayed into
the journal, back to back).  With fsync, a tick is written at once and its
fsync done by the journal's own thread; the line says how many fsyncs that
thread did (one covers every line written before it) and how long closing
waited for the last.

    python benchmarks/bench_journal.py [--dir DIR] [--ticks N]

DIR is where the journal is written (default: where a run on boards keeps
it, $XDG_STATE_HOME/stairbot or ~/.local/state/stairbot): fsync costs what
that disk makes it cost (on tmpfs, nothing).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import sys
import tempfile
import time
from functools import partial
from pathlib import Path
from typing import Any

from stairbot.control.robot_config import load_config
from stairbot.inputs.scenario import load_scenario
from stairbot.run.journal import JournalWriter, mark_path
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import run


def recorded_ticks(n: int) -> list[dict[str, Any]]:
    """The first ``n`` ticks of the default run, as the journal would see them."""
    config, scenario = load_config(), load_scenario()
    session = open_robot("sim://", config, RobotOptions(world=scenario))
    ticks: list[dict[str, Any]] = []

    def on_tick(ctl: Any, snap: Any) -> None:
        if len(ticks) < n:
            ticks.append({"time_s": snap.time_s, "phase": ctl.context.phase,
                          "context": ctl.context.to_dict()})

    run(session, config, on_tick=on_tick)
    session.close()
    return ticks


def measure(folder: Path, ticks: list[dict[str, Any]],
            sync: bool) -> tuple[list[float], int, int, float]:
    fd, name = tempfile.mkstemp(prefix="bench-journal-", suffix=".jsonl", dir=folder)
    os.close(fd)
    try:
        w = JournalWriter(name, fresh=True, sync=sync)
        w.start(url="serial://bench", config="reference", config_sha256="0" * 64,
                scenario="default", mode="full", boards=None, time_s=0.0)
        boards = {"motor": {"serial": 1, "uptime_ms": 0}, "sensor": {"serial": 2, "uptime_ms": 0}}
        command = {"MWF": 1.0, "MWB": 1.0, "MWR": 1.0, "MWL": 1.0, "MTF": 0.0, "MTB": 0.0}
        times = []
        for t in ticks:
            t0 = time.perf_counter()
            w.tick(time_s=t["time_s"], phase=t["phase"], estopped=False, command=command,
                   boards=boards, context=partial(dict, t["context"]))
            times.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        w.close()
        return times, os.path.getsize(name), w.syncs, time.perf_counter() - t0
    finally:
        os.unlink(name)
        with contextlib.suppress(FileNotFoundError):
            os.unlink(mark_path(name))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    state = os.environ.get("XDG_STATE_HOME") or str(Path.home() / ".local" / "state")
    p.add_argument("--dir", type=Path, default=Path(state) / "stairbot")
    p.add_argument("--ticks", type=int, default=3000)
    args = p.parse_args(argv)
    if args.ticks < 1:
        p.error("--ticks must be at least 1")
    args.dir.mkdir(parents=True, exist_ok=True)
    ticks = recorded_ticks(args.ticks)
    print(f"bench_journal: {len(ticks)} ticks of the default run, journal in {args.dir}")
    for sync in (True, False):
        times, size, syncs, closing = measure(args.dir, ticks, sync)
        ordered = sorted(times)
        print(f"  {'fsync' if sync else 'no fsync':8s}  per tick: median "
              f"{statistics.median(times) * 1e6:8.0f} us, p99 "
              f"{ordered[int(0.99 * (len(ordered) - 1))] * 1e6:8.0f} us, max "
              f"{ordered[-1] * 1e6:8.0f} us; {size / len(ticks):.0f} bytes a tick "
              f"(the 20 ms tick: {statistics.median(times) / 0.02 * 100:.2f} %)"
              + (f"; {syncs} fsyncs, close waited {closing * 1e3:.1f} ms" if sync else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
