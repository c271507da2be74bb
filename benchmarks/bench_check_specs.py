"""What a sweep's check of its cases costs: every shipped spec's cases built
and judged (zone, limits, steps expected) on every shipped robot, as
``stairbot sweep`` does before it runs any, timed by CPU per spec.

With ``--dump FILE`` each case's facts are written as a JSON line (spec,
robot, case, facts), so two commits' checks can be compared line by line.

A script that prints figures, not a test: it asserts nothing.  Usage:

    python benchmarks/bench_check_specs.py [--robot NAME ...] [--dump FILE]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import stairbot.inputs
from stairbot.inputs.config import shipped_configs
from stairbot.sweep.cases import check_spec
from stairbot.sweep.spec import parse_spec, with_config


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--robot", action="append", help="a shipped robot (default: every one)")
    ap.add_argument("--dump", metavar="FILE", help="write every case's facts here")
    args = ap.parse_args()
    robots = args.robot or shipped_configs()
    dump = open(args.dump, "w", encoding="utf-8") if args.dump else None  # noqa: SIM115
    folder = Path(stairbot.inputs.__file__).parent / "sweeps"
    specs = sorted(folder.glob("*.toml"))
    print(f"robots: {', '.join(robots)}")
    print(f"{'spec':<20} {'cases':>7} {'CPU s':>8}")
    total_cases, total_cpu = 0, 0.0
    for path in specs:
        base = parse_spec(path.read_text("utf-8"), str(path), folder)
        cases, cpu0 = 0, time.process_time()
        for robot in robots:
            for case in check_spec(with_config(base, robot)):
                cases += 1
                if dump is not None:
                    dump.write(json.dumps([path.name, robot, case.index, case.facts],
                                          sort_keys=True) + "\n")
        cpu = time.process_time() - cpu0
        total_cases, total_cpu = total_cases + cases, total_cpu + cpu
        print(f"{path.name:<20} {cases:>7} {cpu:>8.1f}", flush=True)
    print(f"{'all':<20} {total_cases:>7} {total_cpu:>8.1f}")
    if dump is not None:
        dump.close()


if __name__ == "__main__":
    main()
