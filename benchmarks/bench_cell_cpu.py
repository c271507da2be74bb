"""CPU time of fault-matrix cells (stairbot/fakes/fault_matrix.py), each run
``--runs`` times in this process: one line a run, then each cell's median.

    python benchmarks/bench_cell_cpu.py [--runs 3] [CELL ...]

A CELL is ``FAULT|PHASE|WIRE`` (default: three cells of the CAN wire that
spend their time in the lockstep loop, not waiting out timeouts).  CPU time
(``time.process_time``: every thread of the process) is steadier than wall
time on a shared machine; compare builds by interleaving their runs."""

from __future__ import annotations

import argparse
import statistics
import time

from stairbot.fakes.fault_matrix import run_cell

CELLS = ("drop 5%|cal_turn|can", "late 5%|ascent_lift_second|can",
         "corrupt 1%|ascent_drive_second|can")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("cells", nargs="*", default=list(CELLS))
    args = ap.parse_args()
    for spec in args.cells:
        fault, phase, wire = spec.split("|")
        cpu: list[float] = []
        for _ in range(args.runs):
            c0, t0 = time.process_time(), time.perf_counter()
            cell = run_cell(fault, phase, wire)
            cpu.append(time.process_time() - c0)
            print(f"{spec}: {cell.verdict}, CPU {cpu[-1]:.2f} s, wall "
                  f"{time.perf_counter() - t0:.2f} s", flush=True)
        print(f"{spec}: median CPU {statistics.median(cpu):.2f} s of {args.runs}", flush=True)


if __name__ == "__main__":
    main()
