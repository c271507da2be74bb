"""Heat maps of verdicts over two axes: cells, the terminal picture (rich) and
the PNG (matplotlib, the optional extra ``stairbot[plot]``), with the robot's
limits drawn on both."""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rich.text import Text

from stairbot.sweep.verdict import SEVERITY, VERDICTS
from stairbot.text import printable

COLOURS = {"climbed": "#2ca02c", "descended": "#17becf", "refused": "#1f77b4",
           "came_home": "#8c564b",
           "stranded": "#ffbf00", "wrong": "#b03ab0", "unsafe": "#d62728", "error": "#000000"}
LETTERS = {"climbed": "C", "descended": "D", "refused": "R", "came_home": "H", "stranded": "S",
           "wrong": "W",
           "unsafe": "U", "error": "E"}
RISE_AXES, TREAD_AXES = ("stairs.rise", "max_rise_m"), ("stairs.tread", "min_tread_m")
COMFORT = (0.59, 0.65)  # 2R + T, m: DIN 18065 / IBC / IRC comfort rule (docs/envelope.md)


def label(value: Any) -> Any:
    """A value fit for a heat-map axis: lists and tables (a set of faults) as
    short text, "none" for an empty list."""
    if isinstance(value, list):
        return "; ".join(str(label(v)) for v in value) or "none"
    if isinstance(value, dict):
        return " ".join(str(v) for v in value.values())
    return value


def value_of(record: dict[str, Any], axis: str) -> Any:
    if axis in record.get("axes", {}):
        return label(record["axes"][axis])
    return record.get("facts", {}).get(axis)


@dataclass
class Binning:
    labels: list[str]
    edges: list[float] | None  # numeric: len(labels) + 1 edges; None: categories
    keys: list[Any]

    def index(self, v: Any) -> int | None:
        if self.edges is None:
            return self.keys.index(v) if v in self.keys else None
        if not isinstance(v, int | float):
            return None
        for i in range(len(self.labels)):
            if self.edges[i] <= v < self.edges[i + 1] or (
                    i == len(self.labels) - 1 and v == self.edges[-1]):
                return i
        return None


def binning(values: list[Any], bins: int) -> Binning:
    distinct = sorted({v for v in values if v is not None}, key=lambda v: (str(type(v)), v))
    numeric = bool(distinct) and all(isinstance(v, int | float) and not isinstance(v, bool)
                                     for v in distinct)
    if not numeric:
        return Binning([printable(v) for v in distinct], None, distinct)
    if len(distinct) <= 40:
        mids = [(a + b) / 2 for a, b in zip(distinct, distinct[1:], strict=False)]
        half = (distinct[1] - distinct[0]) / 2 if len(distinct) > 1 else 0.5
        tail = (distinct[-1] - distinct[-2]) / 2 if len(distinct) > 1 else 0.5
        edges = [distinct[0] - half, *mids, distinct[-1] + tail]
        return Binning([f"{v:g}" for v in distinct], edges, list(distinct))
    lo, hi = float(distinct[0]), float(distinct[-1])
    width = (hi - lo) / bins or 1.0
    edges = [lo + k * width for k in range(bins + 1)]
    return Binning([f"{(a + b) / 2:.3g}" for a, b in zip(edges, edges[1:], strict=False)],
                   edges, [])


@dataclass
class Grid:
    x: str
    y: str
    bx: Binning
    by: Binning
    cells: list[list[Counter[str]]]  # [row y][col x]
    limits: dict[str, float]

    @staticmethod
    def build(records: list[dict[str, Any]], x: str, y: str, bins: int) -> Grid:
        bx = binning([value_of(r, x) for r in records], bins)
        by = binning([value_of(r, y) for r in records], bins)
        cells: list[list[Counter[str]]] = [[Counter() for _ in bx.labels] for _ in by.labels]
        for r in records:
            i, j = by.index(value_of(r, y)), bx.index(value_of(r, x))
            if i is not None and j is not None:
                cells[i][j][str(r.get("verdict"))] += 1
        facts: dict[str, Any] = next((r.get("facts", {}) for r in records), {})
        limits = {k: float(facts[k]) for k in ("limit_rise_m", "limit_tread_m")
                  if isinstance(facts.get(k), int | float)}
        return Grid(x, y, bx, by, cells, limits)


def worst(cell: Counter[str]) -> str | None:
    if not cell:
        return None
    bad = [v for v in cell if SEVERITY.get(v, 0) > 0]
    if bad:
        return max(bad, key=lambda v: SEVERITY[v])
    return max(cell, key=lambda v: cell[v])


def limit_for(axis: str, limits: dict[str, float]) -> tuple[str, float] | None:
    if axis in RISE_AXES and "limit_rise_m" in limits:
        return "max_step_rise_m", limits["limit_rise_m"]
    if axis in TREAD_AXES and "limit_tread_m" in limits:
        return "min_tread_m", limits["limit_tread_m"]
    return None


def frame(grid: Grid, cell: Callable[[int, int], tuple[str, str]], width: int = 3) -> Text:
    """The map's frame: rows y from high to low, each cell's text (centred in
    ``width`` characters) and style from ``cell(row, column)``, ◀ and ▲
    marking the row and column holding a limit, the column labels written
    downwards.  The limit's name goes beside its ◀ where the row fits in 80
    columns, else under the map."""
    out = Text()
    x_name, y_name = printable(grid.x), printable(grid.y)
    ylim, xlim = limit_for(grid.y, grid.limits), limit_for(grid.x, grid.limits)
    lw = max([len(s) for s in grid.by.labels] + [len(y_name)])
    row_end = f" ◀ {ylim[0]} {ylim[1]:.3f}" if ylim else ""
    if lw + 1 + width * len(grid.bx.labels) + len(row_end) > 80:
        row_end = " ◀"
    out.append(f"{y_name:>{lw}}\n", style="bold")
    for i in reversed(range(len(grid.by.labels))):
        out.append(f"{grid.by.labels[i]:>{lw}} ")
        for j in range(len(grid.bx.labels)):
            mark, style = cell(i, j)
            out.append(f"{mark:^{width}}", style=style)
        if ylim and grid.by.edges and grid.by.edges[i] <= ylim[1] < grid.by.edges[i + 1]:
            out.append(row_end)
        out.append("\n")
    out.append(" " * (lw + 1))
    for j in range(len(grid.bx.labels)):
        e = grid.bx.edges
        hit = xlim and e and e[j] <= xlim[1] < e[j + 1]
        out.append(f"{'▲' if hit else ' ':^{width}}")
    out.append("\n")
    labels = [lab[:8] for lab in grid.bx.labels]
    for k in range(max((len(lab) for lab in labels), default=0)):  # column labels, vertical
        out.append(" " * (lw + 1) + "".join(f"{lab[k] if k < len(lab) else ' ':^{width}}"
                                            for lab in labels) + "\n")
    out.append(" " * (lw + 1) + x_name + (f"  (▲ {xlim[0]} {xlim[1]:.3f})" if xlim else "")
               + (f"  (◀ {ylim[0]} {ylim[1]:.3f})" if ylim and row_end == " ◀" else "")
               + "\n")
    return out


def terminal(grid: Grid) -> Text:
    """The verdict map: a cell is the worst verdict's letter on its colour
    (count of non-passing cases when more than one), · where no case fell."""
    def cell(i: int, j: int) -> tuple[str, str]:
        c = grid.cells[i][j]
        w = worst(c)
        if w is None:
            return "·", ""
        bad = sum(n for v, n in c.items() if SEVERITY.get(v, 0) > 0)
        return LETTERS[w] + (str(min(bad, 9)) if bad > 1 else " "), f"bold white on {COLOURS[w]}"

    out = frame(grid, cell)
    for v in VERDICTS:
        out.append(f" {LETTERS[v]} ", style=f"bold white on {COLOURS[v]}")
        out.append(f" {v} ")
    out.append("\n")
    return out


def cell_edges(grid: Grid) -> tuple[list[float], list[float]]:
    """The cells' edges in plot units: a numeric axis's bin edges, a category
    axis's positions 0, 1, ... +- 0.5."""
    ex = grid.bx.edges or [k - 0.5 for k in range(len(grid.bx.labels) + 1)]
    ey = grid.by.edges or [k - 0.5 for k in range(len(grid.by.labels) + 1)]
    return ex, ey


def decorate(ax: Any, grid: Grid, title: str, margins: tuple[float, float]) -> None:
    """What every heat-map PNG draws around its cells: the axes' extent and
    labels, the robot's limits (solid) with the verdict rules' margins
    (dotted), the comfort rule on a tread x rise map, and the title."""
    ex, ey = cell_edges(grid)
    ax.set_xlim(ex[0], ex[-1])
    ax.set_ylim(ey[0], ey[-1])
    if grid.bx.edges is None:
        ax.set_xticks(range(len(grid.bx.labels)), grid.bx.labels)
    if grid.by.edges is None:
        ax.set_yticks(range(len(grid.by.labels)), grid.by.labels)
    for axis, line, margin in ((grid.y, ax.axhline, margins[0]), (grid.x, ax.axvline, margins[1])):
        lim = limit_for(axis, grid.limits)
        if lim:
            line(lim[1], color="black", linewidth=2, label=f"{lim[0]} = {lim[1]:.3f} m")
            line(lim[1] - margin, color="black", linewidth=0.8, linestyle=":")
            line(lim[1] + margin, color="black", linewidth=0.8, linestyle=":")
    if grid.x in TREAD_AXES and grid.y in RISE_AXES:
        for s in COMFORT:  # 2R + T = s  ->  R = (s - T) / 2
            ax.plot([ex[0], ex[-1]], [(s - ex[0]) / 2, (s - ex[-1]) / 2], color="grey",
                    linestyle="--", linewidth=1)
        ax.plot([], [], color="grey", linestyle="--", label="2R+T = 0.59 / 0.65 m (comfort rule)")
    ax.set_xlabel(grid.x)
    ax.set_ylabel(grid.y)
    ax.set_title(title, fontsize=10)


def png(grid: Grid, path: Path, title: str, margins: tuple[float, float]) -> Path:
    """Write the heat map as a PNG.  Raises ExtraMissing without matplotlib."""
    plt = pyplot()
    from matplotlib.colors import to_rgba
    from matplotlib.patches import Patch, Rectangle

    fig, ax = plt.subplots(figsize=(9, 6.5), dpi=110)
    ex, ey = cell_edges(grid)
    small = len(grid.bx.labels) * len(grid.by.labels) <= 400
    for i, row in enumerate(grid.cells):
        for j, cell in enumerate(row):
            w = worst(cell)
            if w is None:
                continue
            ax.add_patch(Rectangle((ex[j], ey[i]), ex[j + 1] - ex[j], ey[i + 1] - ey[i],
                                   facecolor=to_rgba(COLOURS[w], 0.85), edgecolor="white",
                                   linewidth=0.5))
            bad = sum(n for v, n in cell.items() if SEVERITY.get(v, 0) > 0)
            if small and bad:
                ax.text((ex[j] + ex[j + 1]) / 2, (ey[i] + ey[i + 1]) / 2,
                        f"{bad}/{sum(cell.values())}", ha="center", va="center", fontsize=6,
                        color="white")
    decorate(ax, grid, title, margins)
    handles = [Patch(color=COLOURS[v], label=v) for v in VERDICTS]
    lines, labels = ax.get_legend_handles_labels()
    ax.legend(handles=handles + lines, labels=list(VERDICTS) + labels, fontsize=7,
              loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return save(fig, path)


def pyplot() -> Any:
    """matplotlib.pyplot on the Agg backend (files only, no window).  Raises
    ExtraMissing without matplotlib."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        from stairbot.sweep.execute import ExtraMissing
        raise ExtraMissing("the PNG heat map", "plot") from None
    return plt


def save(fig: Any, path: Path) -> Path:
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    import matplotlib.pyplot as plt
    plt.close(fig)
    return path
