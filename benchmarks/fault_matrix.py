"""Run the fault matrix (stairbot/fakes/fault_matrix.py) and print it as the
table of docs/reliability.md: one row a fault, one column a phase, one
letter a cell -- C completed, S stopped safe (lifts holding, a reason, a
resumable journal), R resumed (the host killed, a new host finished the
run), F refused (the host killed, the new host refused to resume before
any Clear, the boards still latched), U untested (the run ended safely
before its phase came, on each of its tries), X UNSAFE (listed below the
table with what was wrong).

    python benchmarks/fault_matrix.py [-j 4] [--wire can|serial|firmware] [--fault NAME]
                                      [--phase NAME] [--tries N]

``--wire firmware`` runs the cells on the boards' C firmware (built once with
make into firmware/build) on the serial wire.

A cell whose run ended before its phase (a loaded machine's timeouts:
they are wall time) is run again, up to ``--tries`` times in all; the
counts say how many cells needed it.

Exit status 1 when any cell is unsafe or never had its fault injected.
Most of a cell's time is the host waiting out timeouts, so -j may exceed
the cores."""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

from stairbot.fakes.fault_matrix import ALL_WIRES, FAULTS, PHASES, WIRES, run_cell
from stairbot.fakes.fault_rig import Cell
from stairbot.fakes.firmware_boards import build_native

LETTER = {"completed": "C", "stopped": "S", "resumed": "R", "refused": "F", "untested": "U",
          "UNSAFE": "X"}


def _one(args: tuple[str, str, str, int, Path | None]) -> Cell:
    fault, phase, wire, seed, firmware_dir = args
    return run_cell(fault, phase, wire, seed, firmware_dir=firmware_dir)


def table(cells: list[Cell], wire: str) -> list[str]:
    by = {(c.fault, c.phase): c for c in cells if c.wire == wire}
    phases = [p for p in PHASES if any(k[1] == p for k in by)]
    faults = [f for f in FAULTS if any(k[0] == f for k in by)]
    head = ["fault"] + [str(i + 1) for i, _ in enumerate(phases)]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for f in faults:
        row = [f] + [LETTER[by[f, p].verdict] if (f, p) in by else " " for p in phases]
        lines.append("| " + " | ".join(row) + " |")
    lines.append("")
    lines.append("phases: " + ", ".join(f"{i + 1} {p}" for i, p in enumerate(phases)))
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-j", "--jobs", type=int, default=4)
    ap.add_argument("--wire", choices=ALL_WIRES, action="append",
                    help="default: can and serial; firmware = the C boards, built natively")
    ap.add_argument("--fault", choices=sorted(FAULTS), action="append")
    ap.add_argument("--phase", choices=PHASES, action="append")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--tries", type=int, default=3,
                    help="runs at most of a cell that ends before its phase (default 3)")
    args = ap.parse_args(argv)
    if args.tries < 1:
        ap.error(f"--tries must be 1 or more, not {args.tries}")
    firmware_dir = build_native() if "firmware" in (args.wire or ()) else None
    todo = [(f, p, w, args.seed, firmware_dir) for w in (args.wire or WIRES)
            for f in (args.fault or FAULTS) for p in (args.phase or PHASES)]
    t0 = time.perf_counter()
    cells: list[Cell] = []
    again: Counter[int] = Counter()  # cells by the try that tested them
    with ProcessPoolExecutor(args.jobs) as pool:
        futures = {pool.submit(_one, t): (t, 1) for t in todo}
        done = 0
        while futures:
            fut = next(as_completed(futures))
            task, tried = futures.pop(fut)
            c = fut.result()
            print(f"[{done + 1}/{len(todo)}] {c.wire:8} {c.fault:20} {c.phase:22} "
                  f"{c.verdict:9} {c.wall_s:5.1f} s {c.reason[:90]}", file=sys.stderr,
                  flush=True)
            if c.verdict == "untested" and tried < args.tries:
                futures[pool.submit(_one, task)] = (task, tried + 1)
                continue
            done += 1
            again[tried] += 1
            cells.append(c)
    for wire in args.wire or WIRES:
        print(f"\n## {wire}\n")
        print("\n".join(table(cells, wire)))
    counts = Counter(c.verdict for c in cells)
    print(f"\n{len(cells)} cells in {time.perf_counter() - t0:.0f} s: "
          + ", ".join(f"{k} {counts[k]}" for k in ("completed", "stopped", "resumed",
                                                   "untested", "UNSAFE")))
    if len(again) > 1:
        print("run again after ending before their phase: "
              + ", ".join(f"{n} cell(s) {k - 1} time(s)" for k, n in sorted(again.items())
                          if k > 1))
    bad = [c for c in cells if not c.safe or c.verdict == "untested"]
    for c in bad:
        print(f"{c.verdict} {c.wire} {c.fault} in {c.phase}: {c.reason}")
    stops = Counter((c.fault, c.reason.split(": ", 1)[-1][:60]) for c in cells
                    if c.verdict == "stopped")
    for (fault, reason), n in sorted(stops.items()):
        print(f"stopped ×{n}: {fault}: {reason}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
