"""`stairbot sweep report RESULTS --margin NAME`: the map of a margin's least
value per cell, after the verdict map, and its PNG beside the verdict PNG.

On a results folder written by hand (known margins in known cells), so the
least of each cell is known; one tiny real sweep checks that `stairbot sweep
SPEC --margin NAME` draws it at the end too."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from stairbot.sweep.heatmap import Grid
from stairbot.sweep.margin_map import FIELDS, MarginGrid, cell_text

ROOT = Path(__file__).parents[2]
ENV = {**os.environ, "PYTHONPATH": str(ROOT), "COLUMNS": "80"}

# (rise, tread, verdict, stability_m, edge_m): two rises x two treads, two or
# three cases a cell.  The least stability per cell, in mm:
#   rise 0.20: tread 0.25 -> 4.2, tread 0.30 -> 31
#   rise 0.15: tread 0.25 -> 12,  tread 0.30 -> 19 (the error case has no result)
# edge_m is null in every case of (0.20, 0.30): that cell has no edge margin.
CASES = [
    (0.15, 0.25, "climbed", 0.0171, 0.0031),
    (0.15, 0.25, "climbed", 0.0123, 0.0052),
    (0.15, 0.30, "climbed", 0.0188, 0.0044),
    (0.15, 0.30, "error", None, None),
    (0.20, 0.25, "climbed", 0.0300, 0.0011),
    (0.20, 0.25, "unsafe", 0.0042, 0.0007),
    (0.20, 0.25, "climbed", 0.0555, 0.0020),
    (0.20, 0.30, "refused", 0.0310, None),
    (0.20, 0.30, "refused", 0.0402, None),
]


def record(case: int, rise: float, tread: float, verdict: str, stability: float | None,
           edge: float | None) -> dict[str, Any]:
    result = None if stability is None else {
        "margins": {"stability_m": stability, "pitch_deg": 10.0 + case, "edge_m": edge,
                    "stroke_m": 0.05, "sensor_holds": 0}}
    return {"case": case, "axes": {"stairs.rise": rise, "stairs.tread": tread},
            "facts": {"limit_rise_m": 0.202, "limit_tread_m": 0.26, "zone": "inside"},
            "verdict": verdict, "why": "made by hand", "result": result}


@pytest.fixture
def results(tmp_path: Path) -> Path:
    folder = tmp_path / "results"
    folder.mkdir()
    meta = {"name": "hand", "hash": "0" * 64, "total": len(CASES),
            "axes": [{"path": "stairs.rise", "kind": "list", "describe": "list of 2",
                      "extent": {"count": 2}},
                     {"path": "stairs.tread", "kind": "list", "describe": "list of 2",
                      "extent": {"count": 2}}],
            "rules": {"rise_margin_m": 0.01, "tread_margin_m": 0.01, "home_m": 0.05},
            "report": {"x": "stairs.tread", "y": "stairs.rise", "worst": 3, "bins": 12}}
    (folder / "sweep.json").write_text(json.dumps(meta), "utf-8")
    with (folder / "cases.jsonl").open("w", encoding="utf-8") as f:
        for k, c in enumerate(CASES):
            f.write(json.dumps(record(k, *c)) + "\n")
    return folder


def stairbot(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "stairbot", *args], cwd=ROOT, env=ENV,
                          capture_output=True, text=True, timeout=300)


def margin_rows(stdout: str, name: str) -> dict[str, list[str]]:
    """The margin map's rows, by the row's label: its cells' texts."""
    lines = stdout.splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith(f"least {name} per cell"))
    rows: dict[str, list[str]] = {}
    for line in lines[start + 2:]:
        label, _, rest = line.strip().partition(" ")
        if not label.replace(".", "").isdigit():
            break
        rows[label] = rest.split()[:2]
    return rows


def test_the_terminal_map_shows_each_cells_least_margin(results: Path) -> None:
    rep = stairbot("sweep", "report", str(results), "--margin", "stability_m", "--no-png")
    assert rep.returncode == 1, rep.stderr  # an unsafe case: exit 1 as without --margin
    out = rep.stdout
    # the verdict map first, the margin map after it
    assert out.index(" C  climbed") < out.index("least stability_m per cell, in mm")
    assert margin_rows(out, "stability_m") == {"0.2": ["4.2", "31.0"], "0.15": ["12.3", "18.8"]}
    assert "up to 31 mm" in out and "shades from 4.2" in out
    edge = stairbot("sweep", "report", str(results), "--margin", "edge_m", "--no-png")
    # 0.7 mm is the least at (0.20, 0.25); (0.20, 0.30) has cases but no edge margin
    assert margin_rows(edge.stdout, "edge_m") == {"0.2": ["0.7", "-"], "0.15": ["3.1", "4.4"]}
    holds = stairbot("sweep", "report", str(results), "--margin", "pitch_deg", "--no-png")
    # pitch_deg is 10 + the case's index: the least is the cell's first case
    assert margin_rows(holds.stdout, "pitch_deg") == {"0.2": ["14.0", "17.0"],
                                                      "0.15": ["10.0", "12.0"]}


def test_margin_grid_takes_the_least_of_the_cases_that_have_it() -> None:
    records = [record(k, *c) for k, c in enumerate(CASES)]
    grid = Grid.build(records, "stairs.tread", "stairs.rise", 12)
    mg = MarginGrid.build(records, grid, "edge_m")
    assert mg.least == [[pytest.approx(3.1), pytest.approx(4.4)], [pytest.approx(0.7), None]]
    assert mg.counted == 6  # the error case and the two refusals have no edge margin
    assert [cell_text(v) for v in (0.04, 5.84, 9.96, 16.5, -3.2, 1234.0, -123.0)] == [
        "0.0", "5.8", "10", "17", "-3", "999", "-99"]
    assert [cell_text(v, 4) for v in (16.54, -3.2, 99.96, -12.0, 12345.0)] == [
        "16.5", "-3.2", "100", "-12", "9999"]


def test_the_png_is_written_beside_the_verdict_png(results: Path, tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    rep = stairbot("sweep", "report", str(results), "--margin", "stability_m")
    assert f"heat map: {results / 'heatmap-stability_m.png'}" in rep.stdout, rep.stderr
    for name in ("heatmap.png", "heatmap-stability_m.png"):
        data = (results / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
    named = tmp_path / "maps" / "here.png"
    rep = stairbot("sweep", "report", str(results), "--margin", "edge_m", "--png", str(named))
    assert named.is_file() and (tmp_path / "maps" / "here-edge_m.png").is_file(), rep.stderr


@pytest.mark.parametrize("where", [["report", "RESULTS"], ["sweeps/quick.toml"]])
def test_a_bad_margin_name_is_one_line_and_exit_2(results: Path, where: list[str]) -> None:
    args = [str(results) if a == "RESULTS" else a for a in where]
    rep = stairbot("sweep", *args, "--margin", "stability")
    assert rep.returncode == 2 and rep.stdout == ""
    assert len(rep.stderr.strip().splitlines()) == 1, rep.stderr
    assert "'stability' is not a margin" in rep.stderr
    assert all(name in rep.stderr for name in FIELDS)
    assert not (results / "heatmap.png").exists()


def test_a_sweep_draws_the_margin_map_at_the_end(tmp_path: Path) -> None:
    spec = tmp_path / "tiny.toml"
    spec.write_text('[sweep]\nname = "tiny"\nseed = 3\ncases = 1\n\n[axes]\n'
                    '"stairs.rise" = [0.12, 0.16]\n"stairs.tread" = [0.30]\n'
                    '"stairs.count" = 1\n\n[report]\nx = "stairs.tread"\ny = "stairs.rise"\n',
                    "utf-8")
    out = tmp_path / "out"
    rep = stairbot("sweep", str(spec), "-j", "1", "--out", str(out), "--no-png",
                   "--margin", "stroke_m")
    lines = [json.loads(x) for x in (out / "cases.jsonl").read_text("utf-8").splitlines()]
    want = {f"{r['axes']['stairs.rise']:g}":
            [cell_text(1000 * r["result"]["margins"]["stroke_m"], 4)] for r in lines}
    rows = {k: v[:1] for k, v in margin_rows(rep.stdout, "stroke_m").items()}
    assert rows == want, rep.stdout + rep.stderr
