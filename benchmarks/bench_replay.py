"""What ``stairbot replay`` costs: loading a recording (wall time and peak
memory of a fresh process, each round), and what a redraw of the console
costs the player -- moving the position by a tenth of a second of clock and
writing the ticks and events up to there into the live state -- at 1x, 10x
and 50x over the whole recording, and seeking to the end and back.

    python benchmarks/bench_replay.py [FILE.mcap] [--rounds N]

Without FILE the default run is recorded first (stairbot run --record, in a
temporary folder).  The screen's own drawing (Textual) is not in these
figures.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from stairbot.console.replay import ReplayPlayer
from stairbot.recording.replay_load import load_replay

LOAD = ("import resource, sys, time\n"
        "t = time.perf_counter()\n"
        "from stairbot.recording.replay_load import load_replay\n"
        "s = load_replay(sys.argv[1])\n"
        "print(time.perf_counter() - t, len(s.ticks), "
        "resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)\n")


def load_round(path: Path) -> tuple[float, int, int]:
    """(seconds, ticks, peak kB) of loading ``path`` in a fresh process."""
    out = subprocess.run([sys.executable, "-c", LOAD, str(path)], check=True,
                         capture_output=True, text=True).stdout.split()
    return float(out[0]), int(out[1]), int(out[2])


def redraws(path: Path, speed: float) -> list[float]:
    """Seconds each redraw's update took, playing the whole recording."""
    source = load_replay(path)
    assert source.config is not None
    clock = [0.0]
    player = ReplayPlayer(source, source.config, lambda: clock[0], speed=speed)
    out = []
    while player.playing:
        clock[0] += 0.1  # the console redraws ten times a second
        start = time.perf_counter()
        player.update()
        player.state.view()
        out.append(time.perf_counter() - start)
    return out


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("file", nargs="?", help="an MCAP recording (default: record the default run)")
    p.add_argument("--rounds", type=int, default=3)
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(args.file) if args.file else Path(tmp) / "run.mcap"
        if not args.file:
            subprocess.run([sys.executable, "-m", "stairbot", "run", "-q", "--record",
                            str(path)], check=True, stdout=subprocess.DEVNULL)
        size = path.stat().st_size
        rounds = [load_round(path) for _ in range(args.rounds)]
        times = [r[0] for r in rounds]
        print(f"{path.name}: {size / 1e6:.2f} MB, {rounds[0][1]} ticks")
        print(f"load: median {statistics.median(times):.2f} s "
              f"({', '.join(f'{t:.2f}' for t in times)}), peak "
              f"{statistics.median(r[2] for r in rounds) / 1000:.0f} MB")
        for speed in (1.0, 10.0, 50.0):
            d = redraws(path, speed)
            print(f"redraw at {speed:g}x: median {statistics.median(d) * 1e3:.2f} ms, "
                  f"max {max(d) * 1e3:.2f} ms over {len(d)} redraws")
        source = load_replay(path)
        assert source.config is not None
        player = ReplayPlayer(source, source.config, time.monotonic, playing=False)
        ends, starts = [], []
        for _ in range(5):
            t = time.perf_counter()
            player.seek(player.end_s)
            ends.append(time.perf_counter() - t)
            t = time.perf_counter()
            player.seek(player.start_s)
            starts.append(time.perf_counter() - t)
        print(f"seek to the end: median {statistics.median(ends) * 1e3:.1f} ms; "
              f"to the start: {statistics.median(starts) * 1e3:.1f} ms (5 each)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
