"""Run the fault matrix (stairbot/fakes/fault_matrix.py) and print it as the
table of docs/reliability.md: one row a fault, one column a phase, one
letter a cell -- C completed, S stopped safe (lifts holding, a reason, a
resumable journal), R resumed (the host killed, a new host finished the
run), F refused (the host killed, the new host refused to resume before
any Clear, the boards still latched), X UNSAFE (listed below the table with
what was wrong).

    python benchmarks/fault_matrix.py [-j 4] [--wire can|serial|firmware] [--fault NAME]
                                      [--phase NAME]

``--wire firmware`` runs the cells on the boards' C firmware (built once with
make into firmware/build) on the serial wire.

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

LETTER = {"completed": "C", "stopped": "S", "resumed": "R", "refused": "F", "UNSAFE": "X"}


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
    args = ap.parse_args(argv)
    firmware_dir = build_native() if "firmware" in (args.wire or ()) else None
    todo = [(f, p, w, args.seed, firmware_dir) for w in (args.wire or WIRES)
            for f in (args.fault or FAULTS) for p in (args.phase or PHASES)]
    t0 = time.perf_counter()
    cells: list[Cell] = []
    with ProcessPoolExecutor(args.jobs) as pool:
        futures = [pool.submit(_one, t) for t in todo]
        for i, fut in enumerate(as_completed(futures), 1):
            c = fut.result()
            cells.append(c)
            print(f"[{i}/{len(todo)}] {c.wire:8} {c.fault:20} {c.phase:22} {c.verdict:9} "
                  f"{c.wall_s:5.1f} s {c.reason[:90]}", file=sys.stderr, flush=True)
    for wire in args.wire or WIRES:
        print(f"\n## {wire}\n")
        print("\n".join(table(cells, wire)))
    counts = Counter(c.verdict for c in cells)
    print(f"\n{len(cells)} cells in {time.perf_counter() - t0:.0f} s: "
          + ", ".join(f"{k} {counts[k]}" for k in ("completed", "stopped", "resumed", "UNSAFE")))
    bad = [c for c in cells if not c.safe]
    for c in bad:
        print(f"UNSAFE {c.wire} {c.fault} in {c.phase}: {c.reason}")
    stops = Counter((c.fault, c.reason.split(": ", 1)[-1][:60]) for c in cells
                    if c.verdict == "stopped")
    for (fault, reason), n in sorted(stops.items()):
        print(f"stopped ×{n}: {fault}: {reason}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
