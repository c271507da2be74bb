"""How well a sweep uses the cores: cases per minute on the same 100 cases
with 1 and 2 workers, on the local process pool and on a Dask LocalCluster,
and the parallel efficiency (rate with N workers / (N x rate with 1)).

The 100 cases are short (one 0.17 m step, a landing, a fresh noise seed per
case) so the whole benchmark takes a few minutes on 2 cores.  Each executor
first runs one warm-up case per worker (not counted), so the figures are the
steady rate, not the pool's start-up.  "CPU s/case" is the workers' own CPU
time per case: equal for 1 and 2 workers means the sweep adds no work when
it runs in parallel, and a lower efficiency is the cores being shared.  With
--repeat N each figure is the median of N runs.  The load average before and
after is printed: other work on the machine lowers the 2-worker figures first.

With ``--spec FILE`` it measures a shipped spec instead: every ``--every``-th
of its cases (all of them by default) on the local pool with ``-j`` workers,
and prints cases per core-minute (the cases over the workers' CPU minutes,
which the machine's other work barely moves), cases per minute by the wall
clock, the simulated seconds per CPU second, and what the whole spec would
take at that wall rate.  The sample is spread over the whole spec (the grid's
cells are its order), so the envelope's every 10th case is a fair tenth of it.

A script that prints figures, not a test: it asserts nothing.  Usage:

    python benchmarks/bench_sweep.py [--cases 100] [--repeat 1] [--no-dask]
    python benchmarks/bench_sweep.py --spec sweeps/quick.toml [--spec sweeps/envelope.toml
                                     --every 10] [-j 2] [--config NAME]
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from concurrent.futures import wait
from pathlib import Path
from typing import Any

from stairbot.sweep.cases import Case, check_spec
from stairbot.sweep.execute import open_executor, run_cases
from stairbot.sweep.spec import Spec, load_spec, parse_spec, with_config
from stairbot.sweep.store import ResultStore
from stairbot.sweep.worker import run_case

SPEC = """
[sweep]
name = "bench"
seed = 100
cases = {n}
[axes]
"stairs.count" = 1
"sensors.seed" = {{ randint = [1, 1000000] }}
"""


def timed(spec: Spec, cases: list[Case], jobs: int, dask: str | None = None
          ) -> tuple[list[dict[str, Any]], float]:
    """Run ``cases`` of ``spec`` on a fresh executor with ``jobs`` workers, one
    warm-up case per worker first (not counted): the records and the wall
    time the counted cases took."""
    with tempfile.TemporaryDirectory() as tmp, open_executor(jobs, dask) as (ex, _label):
        wait([ex.submit(run_case, cases[k % len(cases)]) for k in range(jobs)])  # warm up
        store = ResultStore(Path(tmp), spec, resume=False)
        t0 = time.perf_counter()
        out = run_cases(cases, store, ex, lambda _r: None, jobs)
        wall = time.perf_counter() - t0
        store.close()
    return out.records, wall


def rate(cases: list[Case], jobs: int, dask: str | None) -> tuple[float, float]:
    """Cases per minute of ``cases`` on a fresh executor with ``jobs`` workers,
    and the workers' mean CPU seconds per case."""
    records, wall = timed(parse_spec(SPEC.format(n=len(cases)), "bench.toml"), cases, jobs, dask)
    cpu = statistics.fmean(r["cpu_s"] for r in records)
    return len(records) / wall * 60.0, cpu


def spec_rate(path: str, every: int, jobs: int, config: str | None) -> None:
    """Print one spec's figures (see the module docstring)."""
    spec = load_spec(path)
    if config is not None:
        spec = with_config(spec, config)
    everything = check_spec(spec)
    cases = everything[::every]
    records, wall = timed(spec, cases, jobs)
    ran = len(records)
    cpu = sum(r["cpu_s"] for r in records)
    simulated = sum((r.get("result") or {}).get("sim_time_s") or 0.0 for r in records)
    per_min = ran / wall * 60.0
    print(f"{spec.name:<10} {ran:>5} of {len(everything):<5} {jobs:>4} "
          f"{ran / cpu * 60.0:>16.1f} {per_min:>10.1f} {simulated / cpu:>12.0f} "
          f"{len(everything) / per_min:>12.1f}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=100)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--no-dask", action="store_true", help="only the local process pool")
    ap.add_argument("--spec", action="append", metavar="FILE",
                    help="measure this spec's cases instead (repeatable)")
    ap.add_argument("--every", type=int, default=1, metavar="K",
                    help="with --spec: every K-th case (default 1: all)")
    ap.add_argument("-j", "--jobs", type=int, default=2, help="with --spec: workers (default 2)")
    ap.add_argument("--config", help="with --spec: the robot (a file or a shipped robot)")
    args = ap.parse_args()
    if args.spec:
        print(f"{os.cpu_count()} cores, load before {os.getloadavg()[0]:.2f}")
        print(f"{'spec':<10} {'cases run':>14} {'jobs':>4} {'cases/core-min':>16} "
              f"{'cases/min':>10} {'sim s/CPU s':>12} {'whole, min':>12}")
        for path in args.spec:
            spec_rate(path, max(1, args.every), args.jobs, args.config)
        print(f"load after {os.getloadavg()[0]:.2f}")
        return
    cases = check_spec(parse_spec(SPEC.format(n=args.cases), "bench.toml"))
    print(f"{len(cases)} cases, {os.cpu_count()} cores, load before "
          f"{os.getloadavg()[0]:.2f}")
    executors: list[tuple[str, str | None]] = [("local pool", None)]
    if not args.no_dask:
        try:
            import distributed  # noqa: F401
            executors.append(("Dask LocalCluster", "local"))
        except ImportError:
            print("Dask: not installed (pip install 'stairbot[dask]'), skipped")
    print(f"{'executor':<20} {'workers':>7} {'cases/min':>10} {'efficiency':>11} "
          f"{'CPU s/case':>11}")
    for name, dask in executors:
        one = 0.0
        for jobs in (1, 2):
            runs = sorted(rate(cases, jobs, dask) for _ in range(args.repeat))
            r, cpu = runs[len(runs) // 2]
            one = one or r
            eff = r / (jobs * one)
            print(f"{name:<20} {jobs:>7} {r:>10.1f} {100 * eff:>10.0f} % {cpu:>11.3f}",
                  flush=True)
    print(f"load after {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
