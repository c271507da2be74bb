"""Default runs over a faulty wire: does the run ride out ordinary link noise?

    python benchmarks/soak_faults.py [--seeds N] [--first-seed S] [--wire serial|can]
                                     [--fault drop|corrupt|late|duplicate]
                                     [--p 0.05] [-j 2] [--url-options OPTS]
                                     [--realtime [--time-scale X]] [--keep DIR]

For each wire, fault and seed it starts ``stairbot fake-boards`` with that
fault at probability P on every frame the boards send or take
(``--fault-seed`` = the seed), then ``stairbot run --robot URL --json`` with
the URL's default options, and prints one line per run (outcome, steps,
fell, what the link counted) and a count per wire and fault, each saying
its mode.  ``--keep DIR`` keeps each run's record (``stairbot run
--record``, JSON lines: every event and tick) and what the boards said,
named by mode, wire, fault and seed.  Serial boards sit on a
pseudo-terminal, CAN boards on ``udp_multicast`` on loopback, each run on a
group of its own.  Exit status 1 if any run did not complete or fell.

Two modes:

* **lockstep** (the default, ``--lockstep`` to the boards): the boards'
  world stands still while the host waits or retries, so a run's physics is
  the same at any machine load; what the faults change is what the host
  hears.  It cannot show whether a watchdog survives the noise: the
  watchdog's clock stands still too.
* **real time** (``--realtime``): the boards run free, paced at
  ``--time-scale X`` times real time (default 1), and count their watchdog in
  that time; the host's clock, timeouts and grace run X times faster too
  (docs/protocol.md, "Riding through noise in real time"), so a run at X is
  the real-time run played X times faster, no more lenient -- provided the
  machine keeps up: the host must do a tick's work in 1/X of a tick, and on
  a loaded machine a host that falls behind trips a watchdog.  Boards that
  fall behind pause their world (``Pacer``) and say so on exit; such a run
  is marked ``boards fell behind real time`` and was not real time
  throughout.  A host that falls behind says so in its ``--json``
  (``host_behind``: ticks that began more than one tick late, and the
  longest lateness, in seconds of the robot's clock); such a run is marked
  ``host fell behind``.  Run a clean run (``--p 0``) at X first, on a quiet
  machine.
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

FAULTS = ("drop", "corrupt", "late", "duplicate")
_groups = itertools.count(1)
_PORT = 43000 + os.getpid() % 2000  # two soaks at once do not share a group and port


@dataclass
class Outcome:
    mode: str
    wire: str
    fault: str
    seed: int
    outcome: str
    climbed: int
    descended: int
    fell: bool
    link: dict[str, int]
    wall_s: float
    error: str | None
    behind: str = ""  # the boards' "fell behind real time ..." on exit, if they did
    host_ticks: int = 0  # the host's ticks that began more than one tick late
    host_longest_s: float = 0.0  # the longest of those latenesses (robot clock)

    @property
    def host_behind(self) -> str:
        """'' unless the host fell behind its ticks; else how far."""
        if not self.host_ticks:
            return ""
        return (f"fell behind {self.host_ticks} tick(s), the longest "
                f"{self.host_longest_s * 1e3:.0f} ms late")

    @property
    def ok(self) -> bool:
        return self.outcome == "completed" and not self.fell


def mode_name(time_scale: float | None) -> str:
    """``lockstep``, or ``real time`` with its pace (None: lockstep)."""
    if time_scale is None:
        return "lockstep"
    return "real time" if time_scale == 1 else f"real time x{time_scale:g}"


def one_run(wire: str, fault: str, p: float, seed: int, url_options: str,
            time_scale: float | None = None, keep: Path | None = None) -> Outcome:
    """One default run; ``time_scale`` None: lockstep, else free-running
    boards paced at that many times real time; ``keep``: a folder for the
    run's record and the boards' output."""
    t0 = time.monotonic()
    where = ["--serial"] if wire == "serial" else [
        "--can", f"udp_multicast/239.74.164.{next(_groups) % 250 + 1}?port={_PORT}"]
    pace = ["--lockstep"] if time_scale is None else ["--time-scale", f"{time_scale:g}"]
    mode = mode_name(time_scale)
    name = f"{mode.replace(' ', '')}_{wire}_{fault}_p{p:g}_seed{seed}"
    record = [] if keep is None else ["--record", str(keep / f"{name}.jsonl")]
    boards = subprocess.Popen(
        [sys.executable, "-m", "stairbot", "fake-boards", *where, *pace,
         f"--{fault}", str(p), "--fault-seed", str(seed)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert boards.stdout is not None
        url = boards.stdout.readline().strip()
        if url_options:
            url += ("&" if "?" in url else "?") + url_options
        # A journal of its own: a run that ends on a lost link leaves its
        # journal resumable, and the next run on a reused pty would be refused.
        with tempfile.TemporaryDirectory() as tmp:
            host = subprocess.run([sys.executable, "-m", "stairbot", "run", "--robot", url,
                                   "--journal", str(Path(tmp) / "journal.jsonl"), "--json",
                                   "-q", *record], capture_output=True, text=True, timeout=1800)
    finally:
        boards.terminate()
        try:
            _, said = boards.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            boards.kill()
            _, said = boards.communicate()
    wall = time.monotonic() - t0
    if keep is not None:
        (keep / f"{name}.boards.txt").write_text(said or "")
    behind = re.search(r"fell behind real time \d+ time\(s\), [\d.]+ s let go", said or "")
    lagged = behind.group(0).strip() if behind else ""
    try:
        r = json.loads(host.stdout)
    except json.JSONDecodeError:
        last = (host.stderr.strip().splitlines() or ["no output"])[-1]
        return Outcome(mode, wire, fault, seed, f"exit {host.returncode}", 0, 0, False, {}, wall,
                       last, lagged)
    link = r.get("link") or {}
    host_behind = r.get("host_behind") or {}  # absent on a simulated clock (lockstep)
    return Outcome(mode, wire, fault, seed, r["outcome"], r["steps_climbed"], r["steps_descended"],
                   bool(r["fell"]), {k: int(v) for k, v in link.items()
                                     if isinstance(v, (int, float)) and not isinstance(v, bool)},
                   wall, r.get("error"), lagged, int(host_behind.get("ticks", 0)),
                   float(host_behind.get("longest_s", 0.0)))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first-seed", type=int, default=1, help="seeds FIRST..FIRST+N-1")
    ap.add_argument("--wire", choices=("serial", "can"), action="append")
    ap.add_argument("--fault", choices=FAULTS, action="append")
    ap.add_argument("--p", type=float, default=0.05, help="probability per frame")
    ap.add_argument("-j", type=int, default=2, help="runs at once")
    ap.add_argument("--url-options", default="", help="added to the boards' URL, e.g. grace=0")
    ap.add_argument("--realtime", action="store_true",
                    help="free-running boards (not lockstep): the watchdogs count real time")
    ap.add_argument("--time-scale", type=float, default=1.0,
                    help="with --realtime: boards and host paced at X times real time")
    ap.add_argument("--keep", type=Path, metavar="DIR",
                    help="keep each run's record (JSON lines) and the boards' output in DIR")
    args = ap.parse_args(argv)
    if args.keep is not None:
        args.keep.mkdir(parents=True, exist_ok=True)
    if args.time_scale != 1.0 and not args.realtime:
        ap.error("--time-scale needs --realtime (lockstep runs as fast as it can)")
    scale = args.time_scale if args.realtime else None
    mode = mode_name(scale)
    wires = args.wire or ["serial", "can"]
    faults = args.fault or ["drop", "corrupt", "late"]
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    jobs = [(w, f, s) for w in wires for f in faults for s in seeds]
    print(f"{len(jobs)} runs, {mode}: wires {wires}, faults {faults} at {args.p:.0%}, "
          f"seeds {seeds.start}..{seeds.stop - 1}, {args.j} at once", flush=True)
    results: list[Outcome] = []
    with ThreadPoolExecutor(args.j) as pool:
        futures = [pool.submit(one_run, w, f, args.p, s, args.url_options, scale,
                               args.keep)
                   for w, f, s in jobs]
        for fut in futures:
            o = fut.result()
            results.append(o)
            keys = ("retries", "revived", "feeds", "lost", "late", "stray", "duplicates",
                    "crc_errors", "error_frames")
            counts = " ".join(f"{k} {o.link[k]}" for k in keys if k in o.link)
            print(f"{o.mode}: {o.wire:6} {o.fault:9} seed {o.seed:2}: {o.outcome:9} up {o.climbed} "
                  f"down {o.descended} fell {o.fell!s:5} {o.wall_s:5.0f} s  {counts}"
                  + (f"  error: {o.error}" if o.error else "")
                  + (f"  boards {o.behind}" if o.behind else "")
                  + (f"  host {o.host_behind}" if o.host_behind else ""), flush=True)
    print()
    bad = 0
    for w in wires:
        for f in faults:
            group = [o for o in results if (o.wire, o.fault) == (w, f)]
            good = sum(o.ok for o in group)
            bad += len(group) - good
            lagged = sum(bool(o.behind) for o in group)
            slow = [o for o in group if o.host_ticks]
            print(f"{mode}: {w:6} {f:9} {args.p:.0%}: {good}/{len(group)} completed, "
                  f"fell {sum(o.fell for o in group)}"
                  + (f"; in {lagged} the boards fell behind real time (the machine did not "
                     "keep up)" if lagged else "")
                  + (f"; in {len(slow)} the host fell behind its ticks ("
                     f"{sum(o.host_ticks for o in slow)} late, the longest "
                     f"{max(o.host_longest_s for o in slow) * 1e3:.0f} ms)" if slow else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
