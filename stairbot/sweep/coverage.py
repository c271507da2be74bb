"""Margins and coverage in a sweep's report, for plain sweeps and searches alike:

* the distribution of each margin over the cases (min, quartiles, max);
* the coverage of each axis: the share of its range's bins that some case
  visited (a numeric axis's range cut into ``[report] bins`` equal bins, or
  fewer when it holds fewer values; a list or choice: the share of its values);
* for a search, the worst cases by its objective (case, axes, margins, verdict).

An axis's extent (what coverage divides by) is written into sweep.json by
:func:`extent`; a folder written without it shows no coverage for that axis.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

from stairbot.sweep.axes import Axis
from stairbot.sweep.objective import MARGINS
from stairbot.sweep.report import draw, print_summary, short
from stairbot.text import printable


def extent(axis: Axis) -> dict[str, Any]:
    """The range an axis covers, for sweep.json: ``low``/``high`` for a numeric
    axis, ``count`` its number of distinct values where it has a finite set."""
    if axis.kind in ("list", "choice", "range"):
        count = len({json.dumps(v, sort_keys=True) for v in axis.values})
        if axis.kind == "range":  # a search visits between its values too: bins
            return {"low": min(axis.values), "high": max(axis.values), "count": count}
        return {"count": count}
    lo, hi = axis.extremes()
    if axis.kind == "randint":
        return {"low": lo, "high": hi, "count": int(hi) - int(lo) + 1}
    return {"low": lo, "high": hi}


def quartiles(values: list[float]) -> tuple[float, float, float, float, float]:
    """min, lower quartile, median, upper quartile, max (inclusive method)."""
    if len(values) == 1:
        v = values[0]
        return v, v, v, v, v
    q1, q2, q3 = statistics.quantiles(values, n=4, method="inclusive")
    return min(values), q1, q2, q3, max(values)


def axis_coverage(records: list[dict[str, Any]], path: str, ext: dict[str, Any],
                  bins: int) -> tuple[int, int] | None:
    """(bins visited, bins) of one axis; None without an extent."""
    seen = [r.get("axes", {}).get(path) for r in records]
    if "low" in ext:
        lo, hi = float(ext["low"]), float(ext["high"])
        n = min(bins, int(ext["count"])) if ext.get("count") else bins
        if hi <= lo:
            return (1 if seen else 0), 1
        hit = set()
        for v in seen:
            if isinstance(v, int | float) and math.isfinite(v):
                hit.add(min(n - 1, max(0, int((float(v) - lo) / (hi - lo) * n))))
        return len(hit), n
    if "count" in ext:
        return len({json.dumps(v, sort_keys=True) for v in seen}), int(ext["count"])
    return None


def _f(v: float | None) -> str:
    return "-" if v is None else f"{v:.4g}"


def print_margins(records: list[dict[str, Any]], meta: dict[str, Any], console: Console) -> None:
    """The margins' distribution and the axes' coverage."""
    if not records:
        return
    t = Table(title="margins over the cases", title_justify="left")
    for col in ("margin", "cases", "min", "q1", "median", "q3", "max"):
        t.add_column(col, justify="left" if col == "margin" else "right")
    rows: list[tuple[str, list[float]]] = [
        (k, [float(m[k]) for r in records
             if (m := (r.get("result") or {}).get("margins") or {}).get(k) is not None])
        for k in MARGINS]
    if meta.get("search"):
        rows.append(("normalised (margin)", [float(r["search"]["margin"]) for r in records
                                             if (r.get("search") or {}).get("margin")
                                             is not None]))
    for name, vals in rows:
        if vals:
            t.add_row(name, str(len(vals)), *(_f(v) for v in quartiles(vals)))
        else:
            t.add_row(name, "0", "-", "-", "-", "-", "-")
    console.print(t)
    bins = int(meta.get("report", {}).get("bins", 12))
    c = Table(title="coverage of each axis (share of its range's bins visited)",
              title_justify="left")
    for col in ("axis", "range", "visited", "share"):
        c.add_column(col)
    for a in meta.get("axes", []):
        ext = a.get("extent")
        got = None if ext is None else axis_coverage(records, a["path"], ext, bins)
        rng = "-" if ext is None else (f"{_f(ext['low'])} .. {_f(ext['high'])}"
                                       if "low" in ext else f"{ext['count']} value(s)")
        if got is None:
            c.add_row(printable(a["path"]), rng, "-", "-")
        else:
            c.add_row(printable(a["path"]), rng, f"{got[0]}/{got[1]}",
                      f"{100 * got[0] / got[1]:.0f} %")
    console.print(c)


def by_score(records: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """A search's cases, lowest score first (no score: last)."""
    def key(r: dict[str, Any]) -> tuple[int, float, int]:
        s = (r.get("search") or {}).get("score")
        return (1, 0.0, r["case"]) if s is None else (0, float(s), r["case"])
    return sorted(records, key=key)


def print_search_worst(records: list[dict[str, Any]], meta: dict[str, Any], console: Console,
                       worst: int) -> None:
    """A search's worst cases by its objective."""
    info = meta.get("search")
    if not info or not records or worst <= 0:
        return
    t = Table(title=printable(f"search: worst {min(worst, len(records))} case(s) by "
                              f"{info.get('objective')} (seed {info.get('seed')})"),
              title_justify="left")
    for col in ("case", "score", "verdict", "margins", "axes"):
        t.add_column(col, overflow="fold")
    for r in by_score(records)[:worst]:
        m = (r.get("result") or {}).get("margins") or {}
        margins = ", ".join(f"{k.split('_')[0]}={_f(m.get(k))}" for k in MARGINS)
        axes = ", ".join(f"{k.split('.')[-1]}={short(v)}" for k, v in r.get("axes", {}).items())
        t.add_row(str(r["case"]), _f((r.get("search") or {}).get("score")),
                  printable(r.get("verdict")), margins, printable(axes))
    console.print(t)



def search_line(records: list[dict[str, Any]], meta: dict[str, Any]) -> str:
    """The end line's part for a search: the lowest score and its case."""
    info = meta.get("search")
    if not info or not records:
        return ""
    best = by_score(records)[0]
    s = (best.get("search") or {}).get("score")
    return (f"; lowest {info.get('objective')} {_f(s)} (case {best['case']}, "
            f"{best.get('verdict')})")


def print_report(records: list[dict[str, Any]], meta: dict[str, Any], folder: Path,
                 console: Console, args: argparse.Namespace, worst: int) -> None:
    """What a sweep prints at its end, and `sweep report` again: the verdict
    table and worst cases, a search's worst by its objective, the margins,
    and the heat maps (``args``: the options cli's ``_plot_options`` adds)."""
    print_summary(records, meta, console, worst)
    print_search_worst(records, meta, console, worst)
    print_margins(records, meta, console)
    for png in draw(records, meta, folder, console, args.x, args.y, args.png,
                    not args.no_png, args.margin):
        print(f"heat map: {printable(png)}")
