"""Run a boundary search on the sweep's machinery and report it.

Each probe is a case of the spec (:func:`~stairbot.sweep.cases.build_case`
with the axis overridden), run by the sweep's executor in rounds
(:func:`~stairbot.sweep.execute.run_cases`) and written to the results
folder as any case is: a line in ``cases.jsonl`` (its ``case`` the probe's
number, its facts naming the point and the search), a failing probe's
scenario in ``failures/``.  At the end ``boundary.json`` holds, for each
point, every bracket, the published limit beside it, the non-monotonic
brackets and the probes, and the same is printed.

What a probe *did* is its verdict, save that ``wrong`` is split into what
the robot did (climbed, refused, came home): a boundary is where the
behaviour changes, right or wrong.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

from stairbot.files import writing
from stairbot.sweep.bisect import Bracket, Search, changes, search
from stairbot.sweep.boundary import Point, Published, Target, published
from stairbot.sweep.cases import DIGITS, Case, build_case
from stairbot.sweep.execute import run_cases
from stairbot.sweep.heatmap import LETTERS
from stairbot.sweep.spec import Spec
from stairbot.sweep.store import ResultStore
from stairbot.sweep.verdict import passing

REPORT = "boundary.json"
MAX_PROBES = 120
"""The most probes one point's search runs (a scan of 12 and two changes
narrowed from 20 mm to 1 mm take about 30)."""


def behaviour(record: dict[str, Any]) -> str:
    """What the robot did in a probe: its verdict, ``wrong`` told apart by
    what it did."""
    verdict = str(record.get("verdict"))
    if verdict != "wrong":
        return verdict
    result = record.get("result") or {}
    facts = record.get("facts") or {}
    if result.get("outcome") == "came_home_degraded":
        return "came_home"
    if facts.get("from_top"):
        return "descended" if result.get("outcome") == "completed" else "refused"
    full = result.get("steps_climbed") == facts.get("expected_steps")
    return "climbed" if result.get("outcome") == "completed" and full else "refused"


@dataclass
class PointResult:
    point: Point
    search: Search
    published: list[Published]
    failing: int


class Prober:
    """Runs probes as cases of the spec, numbering them in order."""

    def __init__(self, spec: Spec, store: ResultStore, executor: Executor, jobs: int,
                 on_record: Callable[[dict[str, Any]], None]) -> None:
        self.spec, self.store, self.executor, self.jobs = spec, store, executor, jobs
        self.on_record = on_record
        self.count = 0
        self.failing = 0
        self.interrupted = False

    def run(self, point: Point, k: int, t: Target, values: list[float]) -> list[str]:
        cases: list[Case] = []
        for v in values:
            case = build_case(self.spec, point.base, (t.axis, v))
            facts = {**case.facts, "boundary": {"axis": t.axis, "value": v, "point": k,
                                                "base_case": point.base}}
            cases.append(replace(case, index=self.count, facts=facts))
            self.count += 1
        out = run_cases(cases, self.store, self.executor, self.on_record, self.jobs)
        if out.interrupted:
            self.interrupted = True
            raise KeyboardInterrupt
        by_case = {r["case"]: r for r in out.records}
        records = [by_case[c.index] for c in cases]
        self.failing += sum(1 for r in records if not passing(str(r["verdict"])))
        return [behaviour(r) for r in records]


def search_point(prober: Prober, spec: Spec, point: Point, k: int, t: Target,
                 per_round: int) -> PointResult:
    before = prober.failing
    found = search(list(t.scan), lambda vs: prober.run(point, k, t, vs), t.tolerance,
                   per_round, MAX_PROBES, t.integer, DIGITS)
    return PointResult(point, found, published(spec, point.base, t), prober.failing - before)


# -- the report ------------------------------------------------------------------


def _fmt(t: Target, v: float) -> str:
    return f"{v:.0f}" if t.integer else f"{v:.4f}"


def _diff(t: Target, v: float) -> str:
    return f"{v * 1000:.1f} mm" if t.metres else f"{v:.4g}"


def nearest(b: Bracket, pubs: list[Published]) -> Published | None:
    """The published limit a bracket between two passing behaviours measures
    (None for a change to a failing one: no limit publishes where a robot
    fails)."""
    if not (passing(b.low_is) and passing(b.high_is)):
        return None
    return min(pubs, key=lambda p: abs(p.value - b.middle), default=None)


def judge_limit(b: Bracket, p: Published) -> tuple[str, float]:
    """("agrees" | "optimistic" | "conservative", how far off): the published
    limit within the bracket agrees; a bracket on the inside side of it means
    the robot's behaviour changes where the rules still promise the inside
    (the published limit is optimistic), on the outside side that it does
    better than published (conservative)."""
    if b.low <= p.value <= b.high:
        return "agrees", 0.0
    off = p.value - b.high if b.high < p.value else b.low - p.value
    inside_below = p.below == "inside"
    inside_above = p.above == "inside"
    if (b.high < p.value and inside_below) or (b.low > p.value and inside_above):
        return "optimistic", off
    if inside_below or inside_above:
        return "conservative", off
    return "off", off


def bracket_dict(t: Target, b: Bracket, pubs: list[Published]) -> dict[str, Any]:
    p = nearest(b, pubs)
    out: dict[str, Any] = {
        "last": {"value": b.low, "behaviour": b.low_is},
        "first": {"value": b.high, "behaviour": b.high_is},
        "width": round(b.width, 9), "middle": round(b.middle, 9),
        "within_tolerance": b.width <= t.tolerance + 1e-12 or t.integer and b.width <= 1,
    }
    out["failing_side"] = [side for side, c in (("last", b.low_is), ("first", b.high_is))
                           if not passing(c)]
    if p is not None and not out["failing_side"]:
        how, off = judge_limit(b, p)
        out["published"] = {"name": p.name, "value": p.value, "zone_below": p.below,
                            "zone_above": p.above}
        out["difference"] = round(b.middle - p.value, 9)
        out["published_is"] = how
        out["off_by"] = round(off, 9)
    return out


def point_dict(t: Target, r: PointResult) -> dict[str, Any]:
    s = r.search
    measured = changes([c for _, c in sorted(s.probes)])
    return {
        "base_case": r.point.base, "held": r.point.held,
        "brackets": [bracket_dict(t, b, r.published) for b in s.brackets],
        "published": [asdict(p) for p in r.published],
        "changes": len(s.brackets), "published_changes": len(r.published),
        "monotonic": s.monotonic,
        # changes between two passing behaviours beyond those the rules make
        "extra_changes": max(0, sum(1 for b in s.brackets if passing(b.low_is)
                                    and passing(b.high_is)) - len(r.published)),
        "non_monotonic": [{"low": g.low, "high": g.high,
                           "probes": [list(pr) for pr in g.probes]} for g in s.tangles],
        "probes": len(s.probes), "rounds": s.rounds, "exhausted": s.exhausted,
        "failing_probes": r.failing, "scan_changes": measured,
        "probe_values": [[v, c] for v, c in s.probes],
    }


def write_report(folder: Path, data: dict[str, Any]) -> Path:
    path = folder / REPORT
    tmp = path.with_suffix(".tmp")
    with writing(tmp, "the boundary report"):
        tmp.write_text(json.dumps(data, indent=2, sort_keys=True) + "\n", "utf-8")
        os.replace(tmp, path)
    return path


STRIP = 64
"""Characters across the axis in a point's strip of probes."""


def strip(t: Target, probes: list[tuple[float, str]], pubs: list[Published]) -> list[str]:
    """The probes along the axis as letters (C climbed, R refused, S stranded,
    ...; ! where probes of two behaviours share a character), the published
    limits marked ^ under them."""
    span = t.high - t.low
    cells = ["."] * STRIP
    for v, c in probes:
        i = min(STRIP - 1, max(0, round((v - t.low) / span * (STRIP - 1))))
        mark = LETTERS.get(c, "?")
        cells[i] = mark if cells[i] in (".", mark) else "!"
    under = [" "] * STRIP
    for p in pubs:
        under[min(STRIP - 1, max(0, round((p.value - t.low) / span * (STRIP - 1))))] = "^"
    pad = " " * len(_fmt(t, t.low))
    return [f"  {_fmt(t, t.low)} {''.join(cells)} {_fmt(t, t.high)}",
            f"  {pad} {''.join(under).rstrip()}"]


def lines(t: Target, k: int, total: int, r: PointResult, d: dict[str, Any]) -> list[str]:
    held = ", ".join(f"{p} = {v}" for p, v in r.point.held.items()) or "the base scenario"
    out = [f"point {k + 1}/{total} ({held}): {d['probes']} probes in {d['rounds']} rounds"]
    out += strip(t, r.search.probes, r.published)
    for b, bd in zip(r.search.brackets, d["brackets"], strict=True):
        text = (f"  {b.low_is} -> {b.high_is} in [{_fmt(t, b.low)}, {_fmt(t, b.high)}] "
                f"(width {_diff(t, b.width)})")
        if "published" in bd:
            pub = bd["published"]
            how = bd["published_is"]
            text += (f"; published {pub['name']} {_fmt(t, pub['value'])}: middle "
                     f"{_diff(t, bd['difference'])} from it, ")
            text += ("inside the bracket" if how == "agrees" else
                     f"{how} by {_diff(t, bd['off_by'])}")
            if how != "agrees" and bd["off_by"] <= t.tolerance:
                text += " (within the tolerance)"
        if bd["failing_side"]:
            text += (f"; FAILING ({' and '.join({b.low_is, b.high_is} - {'climbed', 'refused'})}"
                     ") on one side: a finding, no published limit to compare")
        if not bd["within_tolerance"]:
            text += " [NOT narrowed to the tolerance: probe budget spent]"
        out.append(text)
    if not r.search.brackets:
        only = sorted({c for _, c in r.search.probes})
        out.append(f"  no change of behaviour across {_fmt(t, t.low)}..{_fmt(t, t.high)} "
                   f"(every probe {', '.join(only)})")
    for g in r.search.tangles:
        seq = ", ".join(f"{_fmt(t, v)} {c}" for v, c in g.probes)
        out.append(f"  NON-MONOTONIC in [{_fmt(t, g.low)}, {_fmt(t, g.high)}]: {seq}")
    if d["extra_changes"]:
        out.append(f"  MORE CHANGES THAN PUBLISHED: {len(r.published) + d['extra_changes']} "
                   "changes between passing behaviours where the published limits make "
                   f"{len(r.published)}")
    unmatched = [p for p in r.published
                 if all(nearest(b, r.published) is not p for b in r.search.brackets)]
    for p in unmatched:
        out.append(f"  published {p.name} {_fmt(t, p.value)} ({p.below} -> {p.above}): no "
                   "measured change near it")
    if r.failing:
        out.append(f"  {r.failing} failing probe(s): see failures/ and cases.jsonl")
    return out


# -- the command ------------------------------------------------------------------


def run_boundary(spec: Spec, axis: str, tolerance: float | None, scan: int | None,
                 jobs: int, dask: str | None, out: Path | None, quiet: bool) -> int:
    """``stairbot sweep SPEC --boundary AXIS``: exit 0 when every probe
    passed, 1 when some failed (wrong, stranded, unsafe, error), 130 after
    Ctrl-C.  Raises SpecError (exit 2) for a bad axis, tolerance or folder."""
    import sys

    from stairbot.sweep.boundary import points, target
    from stairbot.sweep.execute import open_executor
    from stairbot.sweep.store import meta_of
    from stairbot.text import printable

    t = target(spec, axis, tolerance, scan)
    pts = points(spec, axis)
    for point in pts:  # both ends must make cases the loaders take, before any runs
        for end in (t.low, t.high):
            build_case(spec, point.base, (axis, end))
    folder = out or Path(f"boundary-{spec.name}-{axis}-{spec.hash[:8]}")
    store = ResultStore(folder, spec, False)
    per_round = max(1, jobs)
    results: list[PointResult] = []
    head = (f"boundary of {axis} in sweep {spec.name}: {len(pts)} point(s), "
            f"{_fmt(t, t.low)}..{_fmt(t, t.high)} scanned at {len(t.scan)} values, tolerance "
            f"{_diff(t, t.tolerance)}, {per_round} probe(s) per bracket a round")
    print(printable(head), flush=True)

    def tick(record: dict[str, Any]) -> None:
        if not quiet:
            v = record["axes"].get(axis)
            print(printable(f"  probe {record['case']}: {axis} = {v}: {record['verdict']}"),
                  file=sys.stderr, flush=True)

    interrupted = False
    try:
        with open_executor(jobs, dask) as (executor, label):
            prober = Prober(spec, store, executor, jobs, tick)
            try:
                for k, point in enumerate(pts):
                    r = search_point(prober, spec, point, k, t, per_round)
                    results.append(r)
                    d = point_dict(t, r)
                    for line in lines(t, k, len(pts), r, d):
                        print(printable(line), flush=True)
            except KeyboardInterrupt:
                interrupted = True
    finally:
        store.close()
    data: dict[str, Any] = {"axis": axis, "tolerance": t.tolerance, "scan": list(t.scan),
            "per_round": per_round, "executor": label, "sweep": meta_of(spec),
            "points": [point_dict(t, r) for r in results], "interrupted": interrupted,
            "probes": prober.count}
    path = write_report(folder, data)
    failing = prober.failing
    tangled = sum(1 for p in data["points"] if not p["monotonic"])
    extra = sum(1 for p in data["points"] if p["extra_changes"])
    print(printable(f"boundary {axis}: {prober.count} probe(s) in {folder} ({path.name}); "
                    f"{failing} failing; {tangled} point(s) non-monotonic; {extra} with more "
                    "changes than published"), flush=True)
    if interrupted:
        return 130
    return 1 if failing else 0
