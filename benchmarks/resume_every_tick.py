"""Record a whole run on fake boards in lockstep (CAN, in this process) with
its journal, then ask, for every tick of that journal, whether a host that
died right after it could be resumed: the journal's state at that tick
passes the resume's checks and its last context restores.  Prints the
ticks, the resumable ones, and per phase those that are not.

    python benchmarks/resume_every_tick.py [--scenario NAME] [--keep FILE]

``--keep FILE`` keeps the journal (its mark beside it, FILE.synced).
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path
from typing import Any

from stairbot.control.robot_config import load_config
from stairbot.errors import StairbotError
from stairbot.fakes.host_kills import journaled_run
from stairbot.inputs.scenario import load_scenario
from stairbot.run.journal import JournalState, mark_path, read_journal
from stairbot.run.resume import check, restored_context


def record(scenario_name: str | None, journal: Path) -> str:
    scenario = load_scenario(scenario_name)
    result, _ = journaled_run("can", scenario, journal)
    return f"{scenario.name}: {result.outcome}, climbed {result.steps_climbed}, " \
           f"descended {result.steps_descended}"


def every_tick(journal: Path) -> tuple[int, Counter[str]]:
    """The ticks, and per phase those a resume would refuse."""
    read_journal(journal)  # the whole journal passes its checks
    records = [json.loads(line) for line in journal.read_bytes().splitlines()]
    start, max_steps = records[0], load_config().algorithm.max_steps
    context: dict[str, Any] | None = None
    ticks, refused = 0, Counter[str]()
    for rec in records:
        if rec["kind"] != "tick":
            continue
        ticks += 1
        context = rec if "context" in rec else context
        assert context is not None
        state = JournalState(str(journal), start, rec, context["context"],
                             float(context["time_s"]), None, boards=rec["boards"])
        try:
            check(state, start["url"], rec["boards"])
            restored_context(state, rec["time_s"] + 1.0, max_steps)
        except StairbotError:
            refused[rec["phase"]] += 1
    return ticks, refused


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", help="a shipped scenario's name or a file (default: the "
                    "default stairs)")
    ap.add_argument("--keep", metavar="FILE", type=Path)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        journal = Path(tmp) / "journal.jsonl"
        t0 = time.perf_counter()
        print(record(args.scenario, journal), f"({time.perf_counter() - t0:.0f} s)")
        t0 = time.perf_counter()
        ticks, refused = every_tick(journal)
        print(f"{ticks} ticks journaled, {ticks - sum(refused.values())} resumable "
              f"({time.perf_counter() - t0:.1f} s to check)")
        for phase, n in refused.most_common():
            print(f"  not resumable in {phase}: {n}")
        if args.keep:
            shutil.copy(journal, args.keep)
            shutil.copy(mark_path(journal), mark_path(args.keep))
    return 1 if refused else 0


if __name__ == "__main__":
    sys.exit(main())
