"""``stairbot sweep SPEC.toml --search N``: the command around
:func:`stairbot.sweep.search.search`: options checked, the results folder
opened (sweep.json records the search), the executor, the report."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
from typing import Any

from rich.console import Console

from stairbot.errors import OutputError
from stairbot.files import writing
from stairbot.sweep.coverage import print_report, search_line
from stairbot.sweep.execute import default_jobs, open_executor
from stairbot.sweep.objective import DEFAULT, check_objective
from stairbot.sweep.report import ProgressView, counts_line, counts_of
from stairbot.sweep.search import Plan, SearchStore, describe, load_optuna, search
from stairbot.sweep.spec import Spec, SpecError
from stairbot.sweep.store import META, ResultsError, meta_of, read_meta, stopped_for_room
from stairbot.sweep.verdict import passing
from stairbot.text import printable


def _check_options(args: argparse.Namespace) -> Plan:
    if args.search is None:
        raise SpecError("--objective", None, "only with --search N; allowed: --search N "
                        "--objective NAME")
    if args.limit is not None:
        raise SpecError("--limit", None, "a search runs --search N cases; allowed: one of "
                        "--limit and --search")
    objective = check_objective(args.objective or DEFAULT)
    return Plan(args.search, objective, args.seed)


def _check_folder(folder: Path, plan: Plan) -> None:
    """A folder that holds another kind of run (a plain sweep, another
    objective or seed) is refused before anything is written."""
    if not (folder / META).exists():
        return
    old = read_meta(folder).get("search")
    if old is None:
        raise ResultsError(str(folder), None, "holds a plain sweep's cases; allowed: a new "
                           "--out folder for a search")
    if old.get("objective") != plan.objective or old.get("seed") != plan.seed:
        raise ResultsError(str(folder), None, f"holds a search of {old.get('objective')} "
                           f"(seed {old.get('seed')}); allowed: the same --objective and "
                           "--seed to --resume it, or a new --out folder")


def _write_meta(folder: Path, meta: dict[str, Any]) -> None:
    path = folder / META
    tmp = path.with_suffix(".tmp")
    with writing(tmp, "the sweep's spec"):
        tmp.write_text(json.dumps(meta, indent=2) + "\n", "utf-8")
        os.replace(tmp, path)


def cmd_search(spec: Spec, args: argparse.Namespace) -> int:
    """Run a search; exit codes as a plain sweep's (stairbot.sweep.cli)."""
    if args.seed is None:
        args.seed = spec.seed
    plan = _check_options(args)
    load_optuna()  # a missing extra is said before anything is written
    jobs = args.jobs or default_jobs()
    folder = args.out or Path(f"sweep-{spec.name}-{spec.hash[:8]}-search-{plan.objective}")
    _check_folder(folder, plan)
    store = SearchStore(folder, spec, args.resume, plan.objective)
    meta = {**meta_of(spec), "total": plan.n, "search": describe(spec, plan, jobs)}
    console = Console()
    try:
        _write_meta(folder, meta)
        with open_executor(jobs, args.dask) as (executor, label):
            view = ProgressView(plan.n, counts_of(store.records),
                                printable(f"{spec.name}: search of {plan.objective} on "
                                          f"{label}"), args.quiet)
            try:
                out = search(spec, plan, store, executor, jobs, view.update)
            finally:
                view.close()
    except OutputError as exc:  # a full disk: the cases already written stay
        raise stopped_for_room(exc, "the search", len(store.done), folder) from None
    finally:
        store.close()
    records = [r for r in store.records if r["case"] < plan.n]
    if not args.quiet:
        print_report(records, meta, folder, console, args, spec.report.worst)
    failing = sum(1 for r in records if not passing(str(r["verdict"])))
    state = "interrupted; rerun with --resume" if out.interrupted else (
        f"{failing} not passing" if failing else "all passing")
    print(printable(f"sweep {spec.name}: search {len(records)}/{plan.n} case(s) in {folder} "
                    f"({out.ran} run now in {out.wall_s:.1f} s; {state}): "
                    f"{counts_line(counts_of(records))}{search_line(records, meta)}"),
          flush=True)
    if out.interrupted:
        return 130
    return 1 if failing else 0
