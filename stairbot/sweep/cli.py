"""``stairbot sweep``: run a sweep spec, or redraw the report of a results folder.

::

    stairbot sweep SPEC.toml [-j N | --dask ADDRESS|local] [--out DIR] [--resume]
    stairbot sweep SPEC.toml --search N [--objective NAME] [--seed S] [...]
    stairbot sweep check SPEC.toml
    stairbot sweep report RESULTS [--x AXIS --y AXIS] [--png FILE] [--margin NAME]

Exit codes: 0 no case unsafe, stranded, wrong or error; 1 some are (the counts
are on the last line); 2 a bad spec, folder or option (one line, nothing ran);
130 stopped by Ctrl-C (what finished is kept: rerun with --resume).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from rich.console import Console

from stairbot.errors import OutputError
from stairbot.inputs.config import shipped_configs
from stairbot.sweep.coverage import print_report, search_line
from stairbot.sweep.margin_map import FIELDS as MARGIN_FIELDS
from stairbot.sweep.margin_map import margin_name
from stairbot.sweep.report import ProgressView, counts_line, counts_of
from stairbot.sweep.spec import Spec, SpecError
from stairbot.sweep.verdict import passing
from stairbot.text import printable

EXIT_OK, EXIT_FAILURES, EXIT_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        raise SpecError(self.prog, None, message)


def _jobs(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if n < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: allowed: 1 or more")
    return n


def _plot_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--x", metavar="AXIS", help="heat map x axis (default: the spec's [report])")
    p.add_argument("--y", metavar="AXIS", help="heat map y axis")
    p.add_argument("--png", metavar="FILE", type=Path,
                   help="where to write the PNG heat map (default: RESULTS/heatmap.png; "
                        "needs stairbot[plot])")
    p.add_argument("--no-png", action="store_true", help="draw the heat map in the terminal only")
    p.add_argument("--margin", metavar="NAME", type=margin_name,
                   help="also a map of that margin's least value per cell (one of "
                        f"{', '.join(MARGIN_FIELDS)}; its PNG beside the verdict map's, "
                        "heatmap-NAME.png)")


def run_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="stairbot sweep", formatter_class=argparse.RawDescriptionHelpFormatter,
                description=__doc__, epilog="The spec format and the verdict rules: "
                "docs/envelope.md.  Shipped specs: sweeps/*.toml.")
    p.add_argument("spec", metavar="SPEC.toml", help="the sweep spec")
    p.add_argument("-j", "--jobs", type=_jobs, help="worker processes (default: one per core)")
    p.add_argument("--dask", metavar="ADDRESS|local",
                   help="run on a Dask scheduler (tcp://HOST:8786), or 'local' for a "
                        "LocalCluster of -j workers (needs stairbot[dask])")
    p.add_argument("--out", metavar="DIR", type=Path,
                   help="results folder (default: ./sweep-NAME-HASH8)")
    p.add_argument("--resume", action="store_true",
                   help="keep the cases already in the results folder, run the rest")
    p.add_argument("--limit", metavar="N", type=_jobs, help="run only the first N cases")
    p.add_argument("--config", metavar="FILE|NAME",
                   help="run the cases on this robot config (a file, or a shipped robot: "
                        f"{', '.join(shipped_configs())}) instead of the spec's")
    p.add_argument("--seed", metavar="S", type=int,
                   help="the spec's [sweep] seed replaced (every draw; a search's sampler)")
    p.add_argument("--search", metavar="N", type=_jobs,
                   help="N cases chosen by an optimiser minimising --objective (needs "
                        "stairbot[search])")
    p.add_argument("--objective", metavar="NAME",
                   help="what --search minimises: margin (default: the smallest normalised "
                        "margin), stability_m, edge_m, stroke_m or pitch_deg")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress, no tables")
    p.add_argument("--boundary", metavar="AXIS",
                   help="find where the verdict changes along AXIS (climbed/refused, "
                        "pass/fail) by scan and bisection, beside the published limit "
                        "(docs/envelope.md, \"Boundaries\")")
    p.add_argument("--tolerance", metavar="MM", type=float,
                   help="with --boundary: bracket width, in mm for an axis in metres "
                        "(default 1 mm), else in the axis's unit")
    p.add_argument("--scan", metavar="N", type=_jobs,
                   help="with --boundary: values scanned across a range the spec does not "
                        "list (default 12, or 10 mm apart on an axis in metres)")
    _plot_options(p)
    return p


def main(argv: Sequence[str]) -> int:
    """Entry point of ``stairbot sweep`` (argv after the word ``sweep``)."""
    argv = list(argv)
    if argv[:1] == ["report"]:
        return cmd_report(argv[1:])
    if argv[:1] == ["check"]:
        return cmd_check(argv[1:])
    return cmd_sweep(argv)


def cmd_check(argv: list[str]) -> int:
    p = _Parser(prog="stairbot sweep check",
                description="Validate a spec: build and check every case, run none.")
    p.add_argument("spec", metavar="SPEC.toml")
    args = p.parse_args(argv)
    from stairbot.sweep.cases import iter_cases
    from stairbot.sweep.spec import load_spec

    spec = load_spec(args.spec)  # refuses a spec of too many cases before building any
    zones = counts_of([{"verdict": c.facts["zone"]} for c in iter_cases(spec)])
    print(f"ok  {printable(args.spec)}: {spec.total} case(s) ({spec.grid_size} grid point(s) "
          f"x {spec.samples_per_point}); inside {zones['inside']}, band {zones['band']}, "
          f"outside {zones['outside']}; hash {spec.hash[:12]}")
    return EXIT_OK


def cmd_sweep(argv: list[str]) -> int:
    args = run_parser().parse_args(argv)
    from stairbot.sweep.cases import check_spec
    from stairbot.sweep.execute import default_jobs, open_executor, run_cases
    from stairbot.sweep.spec import load_spec, with_config
    from stairbot.sweep.store import ResultStore, meta_of, stopped_for_room

    spec = load_spec(args.spec)
    if args.config is not None:
        spec = with_config(spec, args.config)
    if args.seed is not None:
        from stairbot.sweep.search import with_seed

        spec = with_seed(spec, args.seed)
    if args.boundary is not None or args.tolerance is not None or args.scan is not None:
        if args.search is not None or args.objective is not None:
            raise SpecError("--boundary", None, "--boundary and --search each choose the "
                            "cases: give one of them")
        return _boundary(args, spec)
    if args.search is not None or args.objective is not None:
        from stairbot.sweep.search_run import cmd_search

        return cmd_search(spec, args)
    cases = check_spec(spec, args.limit)  # a bad spec never starts work
    jobs = args.jobs or default_jobs()
    folder = args.out or Path(f"sweep-{spec.name}-{spec.hash[:8]}")
    store = ResultStore(folder, spec, args.resume)
    console = Console()
    try:
        with open_executor(jobs, args.dask) as (executor, label):
            view = ProgressView(len(cases), counts_of(store.records),
                                printable(f"{spec.name} on {label}"), args.quiet)
            try:
                out = run_cases(cases, store, executor, view.update, jobs)
            finally:
                view.close()
    except OutputError as exc:  # a full disk: the cases already written stay
        raise stopped_for_room(exc, "the sweep", len(store.done), folder) from None
    finally:
        store.close()
    records = [r for r in store.records if r["case"] < len(cases)]
    meta = meta_of(spec)
    if not args.quiet:
        print_report(records, meta, folder, console, args, spec.report.worst)
    failing = sum(1 for r in records if not passing(str(r["verdict"])))
    rate = f"{out.ran / out.wall_s * 60:.0f} cases/min" if out.wall_s > 0 and out.ran else "-"
    state = "interrupted; rerun with --resume" if out.interrupted else (
        f"{failing} not passing" if failing else "all passing")
    print(printable(f"sweep {spec.name}: {len(records)}/{len(cases)} case(s) in {folder} "
                    f"({out.ran} run now in {out.wall_s:.1f} s, {rate}; {state}): "
                    f"{counts_line(counts_of(records))}"), flush=True)
    if out.interrupted:
        return EXIT_INTERRUPTED
    return EXIT_FAILURES if failing else EXIT_OK


def _boundary(args: argparse.Namespace, spec: Spec) -> int:
    from stairbot.sweep.boundary_run import run_boundary
    from stairbot.sweep.execute import default_jobs

    if args.boundary is None:
        raise SpecError("stairbot sweep", None, "--tolerance and --scan go with --boundary AXIS")
    if args.resume or args.limit is not None:
        raise SpecError("stairbot sweep", None, "--resume and --limit do not go with "
                        "--boundary; allowed: a new --out folder for each search")
    return run_boundary(spec, args.boundary, args.tolerance, args.scan,
                        args.jobs or default_jobs(), args.dask, args.out, args.quiet)


def cmd_report(argv: list[str]) -> int:
    p = _Parser(prog="stairbot sweep report",
                description="Redraw the verdict table, worst cases and heat maps "
                            "from a results folder.")
    p.add_argument("results", metavar="RESULTS", type=Path, help="a sweep results folder")
    p.add_argument("--worst", metavar="N", type=int, help="how many worst cases to list")
    _plot_options(p)
    args = p.parse_args(argv)
    from stairbot.sweep.store import read_meta, read_records

    meta = read_meta(args.results)
    records = list({r["case"]: r for r in read_records(args.results)}.values())
    console = Console()
    worst = args.worst if args.worst is not None else int(meta["report"]["worst"])
    print_report(records, meta, args.results, console, args, worst)
    failing = sum(1 for r in records if not passing(str(r["verdict"])))
    print(printable(f"sweep {meta.get('name')}: {len(records)}/{meta.get('total')} case(s): "
                    f"{counts_line(counts_of(records))}{search_line(records, meta)}"),
          file=sys.stdout)
    return EXIT_FAILURES if failing else EXIT_OK
