"""Heat maps of one margin over two axes (``--margin NAME``): each cell holds
the least value of that margin over the cell's cases that have one
(docs/envelope.md, "Margins"), in the terminal (the value in the cell, on a
shade of its place between the map's least and greatest) and as a PNG (a
colour map with a colour bar, the limits drawn as on the verdict map).

Lengths are shown in millimetres, the pitch margin in degrees, sensor holds
as a count."""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rich.text import Text

from stairbot.sweep.heatmap import Grid, cell_edges, decorate, frame, pyplot, save, value_of
from stairbot.text import printable

FIELDS = ("stability_m", "pitch_deg", "edge_m", "stroke_m", "sensor_holds")
"""The margins a result carries (stairbot/run/margins.py), in its order."""
UNITS = {"stability_m": ("mm", 1000.0), "pitch_deg": ("deg", 1.0), "edge_m": ("mm", 1000.0),
         "stroke_m": ("mm", 1000.0), "sensor_holds": ("holds", 1.0)}
SHADES = ("#440154", "#414487", "#2a788e", "#22a884", "#7ad151", "#fde725")
"""viridis at 0, 1/5 .. 1: perceptually even, readable without colour vision; dark = least."""
INK = ("white", "white", "white", "black", "black", "black")
COLUMNS = 80  # the terminal width the map is made to fit


def margin_name(text: str) -> str:
    """``--margin``'s argument: one of :data:`FIELDS`."""
    if text not in FIELDS:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a margin; allowed: {', '.join(FIELDS)}")
    return text


def margin_of(record: dict[str, Any], name: str) -> float | None:
    """The margin ``name`` of a result line, None where the run has none (a
    null margin, an error without a result)."""
    v = ((record.get("result") or {}).get("margins") or {}).get(name)
    return float(v) if isinstance(v, int | float) and not isinstance(v, bool) else None


@dataclass
class MarginGrid:
    grid: Grid
    """The verdict grid: its bins, limits and cases per cell."""
    name: str
    least: list[list[float | None]]
    """[row y][col x]: the least margin of the cell's cases, in the display
    unit (:data:`UNITS`); None where no case of the cell has the margin."""
    counted: int
    """How many cases have the margin and fall in a cell."""

    @staticmethod
    def build(records: list[dict[str, Any]], grid: Grid, name: str) -> MarginGrid:
        scale = UNITS[name][1]
        least: list[list[float | None]] = [[None for _ in grid.bx.labels]
                                           for _ in grid.by.labels]
        counted = 0
        for r in records:
            m = margin_of(r, name)
            i, j = grid.by.index(value_of(r, grid.y)), grid.bx.index(value_of(r, grid.x))
            if m is None or i is None or j is None:
                continue
            counted += 1
            v = m * scale
            old = least[i][j]
            least[i][j] = v if old is None else min(old, v)
        return MarginGrid(grid, name, least, counted)

    def classes(self) -> list[float]:
        """The shades' bounds: the cell values' sextiles (each shade holds
        about a sixth of the cells, so that a few far values -- a robot that
        refused without lifting stands on all six wheels -- do not crowd the
        rest into one shade), repeated bounds merged; [] when no cell has a
        value, [v, v] when all cells hold v."""
        vals = sorted(v for row in self.least for v in row if v is not None)
        if not vals:
            return []
        n = len(SHADES)
        bounds = [vals[min(len(vals) - 1, round(k * (len(vals) - 1) / n))] for k in range(n + 1)]
        return sorted(set(bounds)) if bounds[0] < bounds[-1] else [vals[0], vals[0]]


def cell_text(v: float, chars: int = 3) -> str:
    """A value in at most ``chars`` (3 or 4) characters: one decimal where it
    fits (0.3, 5.8; with 4 also 16.5, -3.2), whole numbers elsewhere (17,
    -3), clipped to the widest whole numbers that fit."""
    if (0 <= v < 9.95) or (chars >= 4 and -9.95 < v < 99.95):
        return f"{v:.1f}"
    top = 10 ** chars - 1
    return f"{max(-(top // 10), min(top, math.floor(v + 0.5))):d}"


def shade(v: float, bounds: list[float]) -> int:
    """The class of ``v``: k where bounds[k] <= v < bounds[k + 1] (the last
    class holds its upper bound), spread over the shades dark to light."""
    k = sum(1 for b in bounds[1:-1] if v >= b)
    classes = max(1, len(bounds) - 1)
    return round(k * (len(SHADES) - 1) / max(1, classes - 1))


def terminal(mg: MarginGrid) -> Text:
    """The margin map: each cell's least value in the unit of the legend (to
    a tenth where five characters a cell fit in 80 columns), on a shade of
    its class (:meth:`MarginGrid.classes`: dark the least sixth of the
    cells, yellow the greatest); · no case in the cell, - cases but none
    with the margin."""
    bounds = mg.classes()
    grid = mg.grid
    lw = max([len(s) for s in grid.by.labels] + [len(printable(grid.y))])
    chars = 4 if lw + 1 + 5 * len(grid.bx.labels) <= COLUMNS else 3  # and a space between

    def cell(i: int, j: int) -> tuple[str, str]:
        v = mg.least[i][j]
        if v is None:
            return ("-" if grid.cells[i][j] else "·"), ""
        k = shade(v, bounds)
        return cell_text(v, chars), f"{INK[k]} on {SHADES[k]}"

    unit = UNITS[mg.name][0]
    out = Text()
    out.append(f"least {mg.name} per cell, in {unit}\n", style="bold")
    out.append_text(frame(grid, cell, chars + 1))
    if not bounds:
        out.append(f"no case has {mg.name}\n")
        return out
    out.append("shades from")
    for lo in bounds[:-1] or bounds[:1]:  # each swatch shows its class's lower bound
        k = shade(lo, bounds)
        out.append(f" {lo:.3g} ", style=f"{INK[k]} on {SHADES[k]}")
    out.append(f" up to {bounds[-1]:.3g} {unit}\n")
    out.append(f"· no case in the cell, - its cases have no {mg.name}\n")
    return out


def png_path(folder: Path, verdict_png: Path | None, name: str) -> Path:
    """Beside the verdict map: FILE-NAME.png for --png FILE.png, else
    RESULTS/heatmap-NAME.png."""
    if verdict_png is not None:
        return verdict_png.with_name(f"{verdict_png.stem}-{name}{verdict_png.suffix or '.png'}")
    return folder / f"heatmap-{name}.png"


def png(mg: MarginGrid, path: Path, title: str, margins: tuple[float, float]) -> Path:
    """Write the margin map as a PNG: cells coloured by their least value
    (a colour bar in the display unit), hatched where the cell's cases have
    no value, blank where no case fell.  Raises ExtraMissing without
    matplotlib."""
    plt = pyplot()
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch, Rectangle

    grid = mg.grid
    bounds = mg.classes() or [0.0, 1.0]
    if bounds[0] == bounds[-1]:
        bounds = [bounds[0] - 0.5, bounds[0] + 0.5]
    cmap = ListedColormap([SHADES[shade(b, bounds)] for b in bounds[:-1]])
    norm = BoundaryNorm(bounds, cmap.N)
    fig, ax = plt.subplots(figsize=(9, 6.5), dpi=110)
    ex, ey = cell_edges(grid)
    small = len(grid.bx.labels) * len(grid.by.labels) <= 400
    for i, row in enumerate(mg.least):
        for j, v in enumerate(row):
            xy, w, h = (ex[j], ey[i]), ex[j + 1] - ex[j], ey[i + 1] - ey[i]
            if v is None:
                if grid.cells[i][j]:
                    ax.add_patch(Rectangle(xy, w, h, facecolor="none", edgecolor="0.6",
                                           hatch="///", linewidth=0.5))
                continue
            ax.add_patch(Rectangle(xy, w, h, facecolor=SHADES[shade(v, bounds)], edgecolor="white",
                                   linewidth=0.5))
            if small:
                ax.text(xy[0] + w / 2, xy[1] + h / 2, f"{v:.1f}", ha="center", va="center",
                        fontsize=6, color=INK[shade(v, bounds)])
    decorate(ax, grid, title, margins)
    unit = UNITS[mg.name][0]
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, fraction=0.05, pad=0.02,
                       spacing="uniform", ticks=bounds)
    bar.ax.set_yticklabels([f"{b:.3g}" for b in bounds])
    bar.set_label(f"least {mg.name} in the cell, {unit} (bands at the cells' sextiles)")
    lines, labels = ax.get_legend_handles_labels()
    handles = [*lines, Patch(facecolor="none", edgecolor="0.6", hatch="///")]
    ax.legend(handles=handles, labels=[*labels, f"cases without {mg.name}"], fontsize=7,
              loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2)
    return save(fig, path)
