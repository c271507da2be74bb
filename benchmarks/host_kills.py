"""Kill the host at every phase of the fault matrix's flight, at the phase's
first, middle and last tick, on each wire, and resume
(stairbot/fakes/host_kills.py); print one line a kill and the counts:
resumed (the run completed), refused before any Clear (the boards still
latched), UNSAFE (latches cleared and the resume failed, or a resumed run
that did not complete), not killed (the run ended before the kill's tick:
its outcome and error said; the flight is the same every time in lockstep,
so a host that timed out on a machine past its cores, or changed code).

    python benchmarks/host_kills.py [-j 1] [--wire can|serial] [--phase NAME] [--point P]

Exit status 1 when any kill is unsafe.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor, as_completed

from stairbot.fakes.fault_matrix import PHASES, WIRES
from stairbot.fakes.fault_rig import Cell
from stairbot.fakes.host_kills import POINTS, run_kill


def _one(args: tuple[str, str, str]) -> Cell:
    return run_kill(*args)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-j", "--jobs", type=int, default=1)
    ap.add_argument("--wire", choices=WIRES, action="append")
    ap.add_argument("--phase", choices=PHASES, action="append")
    ap.add_argument("--point", choices=POINTS, action="append")
    args = ap.parse_args(argv)
    todo = [(w, p, pt) for w in (args.wire or WIRES) for p in (args.phase or PHASES)
            for pt in (args.point or POINTS)]
    t0 = time.perf_counter()
    cells: list[Cell] = []
    with ProcessPoolExecutor(args.jobs) as pool:
        futures = [pool.submit(_one, t) for t in todo]
        for i, fut in enumerate(as_completed(futures), 1):
            c = fut.result()
            cells.append(c)
            print(f"[{i}/{len(todo)}] {c.wire} {c.phase} {c.fault}: {c.verdict}"
                  + (f" ({c.reason})" if c.reason else "") + f" {c.wall_s:.1f} s", flush=True)
    print()
    for wire in args.wire or WIRES:
        counts = Counter(c.verdict for c in cells if c.wire == wire)
        print(f"{wire}: {sum(counts.values())} kills: " + ", ".join(
            f"{v} {n}" for v, n in sorted(counts.items())))
    print(f"{len(cells)} kills in {time.perf_counter() - t0:.0f} s")
    unsafe = [c for c in cells if not c.safe]
    for c in unsafe:
        print(f"UNSAFE {c.wire} {c.phase} {c.fault}: {c.reason}")
    return 1 if unsafe else 0


if __name__ == "__main__":
    sys.exit(main())
