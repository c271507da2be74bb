"""What a person looks at: the progress line while a sweep runs, and at the end
the verdict counts, the worst cases and the heat maps (``stairbot sweep
report RESULTS`` redraws them from a results folder)."""

from __future__ import annotations

import sys
import time
from collections import Counter
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.markup import escape
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.table import Table

from stairbot.sweep import heatmap
from stairbot.sweep.verdict import SEVERITY, VERDICTS
from stairbot.text import printable

STYLE = {"climbed": "green", "descended": "cyan", "refused": "blue", "came_home": "bright_green",
         "stranded": "yellow",
         "wrong": "magenta", "unsafe": "red", "error": "bold red"}


def plain(value: object) -> str:
    """Text from a spec or a results folder as Rich prints it: control
    characters escaped (:func:`~stairbot.text.printable`), brackets taken
    as themselves rather than as markup."""
    return escape(printable(value))


def counts_of(records: list[dict[str, Any]]) -> Counter[str]:
    return Counter(str(r.get("verdict")) for r in records)


def counts_line(counts: Counter[str], markup: bool = False) -> str:
    parts = []
    for v in VERDICTS:
        text = f"{v} {counts.get(v, 0)}"
        parts.append(f"[{STYLE[v]}]{text}[/]" if markup and counts.get(v) else text)
    return ", ".join(parts)


class ProgressView:
    """A progress bar with counts per verdict and an ETA on a terminal; plain
    lines every 10 s (or 10 %) elsewhere, so CI logs stay short."""

    def __init__(self, total: int, done: Counter[str], label: str, quiet: bool = False) -> None:
        self.total, self.counts, self.quiet = total, Counter(done), quiet
        self.err = Console(stderr=True)
        self.live = sys.stderr.isatty() and not quiet
        self.t0 = self.last = time.monotonic()
        self.start_done = sum(done.values())
        self.progress: Progress | None = None
        if self.live:
            self.progress = Progress(
                TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                TextColumn("{task.fields[counts]}"), TimeElapsedColumn(), TextColumn("eta"),
                TimeRemainingColumn(), console=self.err, transient=False)
            self.task = self.progress.add_task(plain(label), total=total,
                                               completed=self.start_done,
                                               counts=counts_line(self.counts, True))
            self.progress.start()
        elif not quiet:
            print(f"{printable(label)}: {total} cases, {self.start_done} already done",
                  file=sys.stderr, flush=True)

    def update(self, record: dict[str, Any]) -> None:
        self.counts[str(record.get("verdict"))] += 1
        n = sum(self.counts.values())
        if self.progress is not None:
            self.progress.update(self.task, completed=n, counts=counts_line(self.counts, True))
            return
        now = time.monotonic()
        if self.quiet or not (now - self.last >= 10 or n == self.total
                              or n % max(1, self.total // 10) == 0):
            return
        self.last = now
        ran = n - self.start_done
        eta = (now - self.t0) / ran * (self.total - n) if ran else 0.0
        print(f"[{n}/{self.total}] {counts_line(self.counts)}; eta {eta:.0f} s",
              file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.progress is not None:
            self.progress.stop()


def short(value: Any) -> str:
    """An axis value as a table shows it: floats to 4 digits, lists by length."""
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, list):
        return f"[{len(value)} item(s)]"
    return str(value)


def worst_cases(records: list[dict[str, Any]], n: int) -> list[dict[str, Any]]:
    bad = [r for r in records if SEVERITY.get(str(r.get("verdict")), 0) > 0]
    bad.sort(key=lambda r: (-SEVERITY[str(r["verdict"])],
                            -((r.get("result") or {}).get("max_pitch_deg") or 0.0), r["case"]))
    return bad[:n]


def print_summary(records: list[dict[str, Any]], meta: dict[str, Any], console: Console,
                  worst: int) -> None:
    counts = counts_of(records)
    table = Table(title=plain(f"sweep {meta.get('name')}: {len(records)} of "
                              f"{meta.get('total')} case(s)"), title_justify="left")
    table.add_column("verdict")
    table.add_column("cases", justify="right")
    table.add_column("share", justify="right")
    for v in VERDICTS:
        k = counts.get(v, 0)
        share = f"{100 * k / len(records):.1f} %" if records else "-"
        table.add_row(f"[{STYLE[v]}]{v}[/]", str(k), share)
    console.print(table)
    bad = worst_cases(records, worst)
    if not bad:
        return
    wt = Table(title=f"worst {len(bad)} case(s)", title_justify="left")
    for col in ("case", "verdict", "axes", "why", "reproduce"):
        wt.add_column(col, overflow="fold")
    for r in bad:
        axes = ", ".join(f"{k.split('.')[-1]}={short(v)}" for k, v in r.get("axes", {}).items())
        wt.add_row(plain(r["case"]), f"[{STYLE[r['verdict']]}]{r['verdict']}[/]", plain(axes),
                   plain(str(r.get("why", ""))[:90]), plain(r.get("reproduce", "")))
    console.print(wt)


def choose_axes(meta: dict[str, Any], x: str | None, y: str | None) -> tuple[str, str] | None:
    """The heat map's axes: given, else the spec's [report], else the first two
    numeric axes, else the stairs' min tread x max rise."""
    rep = meta.get("report", {})
    x = x or rep.get("x")
    y = y or rep.get("y")
    if x and y:
        return x, y
    paths = [a["path"] for a in meta.get("axes", []) if a["kind"] != "choice"]
    if len(paths) >= 2:
        return x or paths[1], y or paths[0]
    return x or "min_tread_m", y or "max_rise_m"


def draw(records: list[dict[str, Any]], meta: dict[str, Any], folder: Path, console: Console,
         x: str | None = None, y: str | None = None, png: Path | None = None,
         want_png: bool = True, margin: str | None = None) -> list[Path]:
    """The terminal heat map of verdicts, then with ``margin`` the map of that
    margin's least per cell (:mod:`stairbot.sweep.margin_map`); and their PNGs
    (default RESULTS/heatmap.png and RESULTS/heatmap-MARGIN.png) when
    matplotlib is there.  Returns the PNGs written."""
    axes = choose_axes(meta, x, y)
    if axes is None or not records:
        return []
    rep = meta.get("report", {})
    grid = heatmap.Grid.build(records, axes[0], axes[1], int(rep.get("bins", 12)))
    console.print(heatmap.terminal(grid))
    mgrid = None
    if margin is not None:
        from stairbot.sweep import margin_map

        mgrid = margin_map.MarginGrid.build(records, grid, margin)
        console.print(margin_map.terminal(mgrid))
    if not want_png:
        return []
    rules = meta.get("rules", {})
    limit_margins = (float(rules.get("rise_margin_m", 0.01)),
                     float(rules.get("tread_margin_m", 0.01)))
    head = f"sweep {meta.get('name')} ({meta.get('hash', '')[:12]}): {len(records)} cases; "
    from stairbot.sweep.execute import ExtraMissing

    try:
        out = [heatmap.png(grid, png or folder / "heatmap.png",
                           head + counts_line(counts_of(records)), limit_margins)]
        if mgrid is not None:
            out.append(margin_map.png(
                mgrid, margin_map.png_path(folder, png, mgrid.name),
                head + f"least {mgrid.name} per cell ({mgrid.counted} cases have it)",
                limit_margins))
        return out
    except ExtraMissing as exc:
        if png is not None:  # asked for by name: a missing extra is an error
            raise
        console.print(f"no PNG heat map: {exc.problem}")
        return []
