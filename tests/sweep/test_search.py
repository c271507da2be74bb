"""`stairbot sweep SPEC.toml --search N`: an optimiser chooses the cases.

End to end on a tiny spec (a grid axis, two continuous axes, a fault axis
whose second value strands every case), seeded twice, resumed; the objective's
order on records made by hand; the messages for a bad objective and a missing
Optuna."""

from __future__ import annotations

import builtins
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from stairbot.sweep import objective
from stairbot.sweep.objective import FAILED, normalised, score
from stairbot.sweep.verdict import PASSING

ROOT = Path(__file__).parents[2]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
N = 10

# Rise is a grid (it seeds the search); the faults axis's second value loses
# both back sensors half way up the step: every such case ends stranded.
TINY = """
[sweep]
name = "tiny"
seed = 4
[axes]
"stairs.count" = 1
"stairs.rise" = [0.16, 0.19]
"stairs.tread" = { uniform = [0.27, 0.32] }
"start.yaw_deg" = { uniform = [-10.0, 10.0] }
"faults" = [[], [{ at = 30.0, sensor = "SBR", kind = "error" },
                 { at = 30.0, sensor = "SBL", kind = "error" }]]
[report]
x = "stairs.tread"
y = "stairs.rise"
"""


def sweep(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "stairbot", "sweep", *args], cwd=ROOT,
                          env=ENV, capture_output=True, text=True, timeout=600)


def lines(folder: Path) -> list[dict[str, Any]]:
    return [json.loads(x) for x in (folder / "cases.jsonl").read_text("utf-8").splitlines()]


@pytest.fixture(scope="module")
def spec(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("spec") / "tiny.toml"
    path.write_text(TINY, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def first(spec: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("search") / "a"
    proc = sweep(str(spec), "--search", str(N), "--seed", "7", "-j", "2", "--out", str(out),
                 "--no-png")
    assert proc.returncode in (0, 1), proc.stderr
    assert "lowest margin" in proc.stdout.strip().splitlines()[-1], proc.stdout
    return out


def test_a_search_writes_n_cases_with_margins_verdicts_and_scores(first: Path) -> None:
    records = lines(first)
    assert sorted(r["case"] for r in records) == list(range(N))
    meta = json.loads((first / "sweep.json").read_text("utf-8"))
    assert meta["total"] == N and meta["seed"] == 7
    assert meta["search"]["objective"] == "margin" and meta["search"]["seed"] == 7
    assert meta["search"]["grid_seeds"] == 2  # both rises, N / 5 = 2
    for r in records:
        assert set(r["axes"]) == {"stairs.count", "stairs.rise", "stairs.tread",
                                  "start.yaw_deg", "faults"}
        assert 0.27 <= r["axes"]["stairs.tread"] <= 0.32
        assert r["axes"]["stairs.rise"] in (0.16, 0.19)
        assert r["result"]["margins"]["stability_m"] is not None
        assert r["search"]["score"] is not None
        if r["verdict"] in PASSING:
            assert r["search"]["score"] == pytest.approx(r["search"]["margin"])
            assert r["search"]["score"] > FAILED
        else:  # a failing case is written as a plain sweep writes it
            assert r["search"]["score"] < FAILED
            assert (first / "failures" / f"case-{r['case']:06d}.toml").is_file()
    # the first two cases are the grid's two rises
    assert {r["axes"]["stairs.rise"] for r in records if r["case"] < 2} == {0.16, 0.19}
    # the stranding faults are what scores lowest: the search finds them
    assert any(r["verdict"] == "stranded" for r in records)
    rep = sweep("report", str(first), "--no-png")
    assert "search: worst" in rep.stdout and "coverage of each axis" in rep.stdout, rep.stderr
    assert "lowest margin" in rep.stdout.strip().splitlines()[-1]


def test_the_same_seed_chooses_the_same_cases(spec: Path, first: Path, tmp_path: Path) -> None:
    again = tmp_path / "b"
    sweep(str(spec), "--search", str(N), "--seed", "7", "-j", "2", "--out", str(again), "-q")
    a = {r["case"]: (r["axes"], r["verdict"]) for r in lines(first)}
    b = {r["case"]: (r["axes"], r["verdict"]) for r in lines(again)}
    assert a == b
    other = tmp_path / "c"
    sweep(str(spec), "--search", "4", "--seed", "8", "-j", "2", "--out", str(other), "-q")
    assert [r["axes"] for r in lines(other)] != [a[i][0] for i in range(4)]


def test_a_search_on_dask_chooses_the_same_cases(spec: Path, first: Path,
                                                 tmp_path: Path) -> None:
    pytest.importorskip("distributed")
    out = tmp_path / "d"
    proc = sweep(str(spec), "--search", str(N), "--seed", "7", "-j", "2", "--dask", "local",
                 "--out", str(out), "-q")
    assert proc.returncode in (0, 1), proc.stderr
    local = {r["case"]: (r["axes"], r["verdict"], r["search"]) for r in lines(first)}
    assert {r["case"]: (r["axes"], r["verdict"], r["search"]) for r in lines(out)} == local


def test_resume_finishes_to_n_without_repeating_a_case(spec: Path, tmp_path: Path) -> None:
    out = tmp_path / "r"
    sweep(str(spec), "--search", "4", "-j", "2", "--out", str(out), "-q")
    assert len(lines(out)) == 4
    again = sweep(str(spec), "--search", "4", "-j", "2", "--out", str(out), "-q")
    assert again.returncode == 2 and "--resume" in again.stderr  # never mixed silently
    proc = sweep(str(spec), "--search", "8", "-j", "2", "--out", str(out), "-q", "--resume")
    assert proc.returncode in (0, 1), proc.stderr
    records = lines(out)
    assert sorted(r["case"] for r in records) == list(range(8))
    chosen = [json.dumps(r["axes"], sort_keys=True) for r in records]
    assert len(set(chosen)) == 8
    assert json.loads((out / "sweep.json").read_text("utf-8"))["total"] == 8
    # another objective is another search: not mixed into this folder
    other = sweep(str(spec), "--search", "8", "--objective", "edge_m", "--out", str(out),
                  "--resume", "-q")
    assert other.returncode == 2 and "holds a search of margin" in other.stderr


def _rec(verdict: str, **margins: float | None) -> dict[str, Any]:
    return {"verdict": verdict, "result": {"margins": margins}}


SCALE = {"stability_m": 0.02, "edge_m": 0.05, "stroke_m": 0.1, "pitch_deg": 20.0}


def test_a_failing_case_scores_below_every_passing_one() -> None:
    passing = _rec("climbed", stability_m=-0.5, edge_m=-0.04, stroke_m=0.0, pitch_deg=-10.0)
    for name in objective.OBJECTIVES:
        low = score(passing, name, SCALE)
        assert low is not None
        for bad in ("unsafe", "stranded", "wrong", "error"):
            assert score(_rec(bad, stability_m=1.0, edge_m=1.0, stroke_m=1.0, pitch_deg=9.0),
                         name, SCALE) < low
    assert score(_rec("error"), "margin", SCALE) < score(_rec("stranded"), "margin", SCALE)


def test_none_margins_are_left_out_or_score_no_information() -> None:
    never_climbed = _rec("refused", stability_m=0.019, edge_m=None, stroke_m=0.05,
                         pitch_deg=10.0)
    # the default is the least of the others: 0.019 / 0.02 (stroke 0.5, pitch 0.5)
    assert score(never_climbed, "margin", SCALE) == pytest.approx(0.5)
    assert normalised({"stability_m": 0.01, "edge_m": None}, SCALE) == pytest.approx(0.5)
    assert score(never_climbed, "edge_m", SCALE) is None
    assert score(never_climbed, "stability_m", SCALE) == pytest.approx(0.019)
    assert score(_rec("climbed"), "margin", SCALE) is None


def test_a_bad_objective_is_one_clear_message(spec: Path, tmp_path: Path) -> None:
    proc = sweep(str(spec), "--search", "3", "--objective", "tilt", "--out",
                 str(tmp_path / "x"))
    assert proc.returncode == 2
    assert "'tilt' is not an objective; allowed: margin, stability_m, edge_m, stroke_m, " \
           "pitch_deg" in proc.stderr
    assert "Traceback" not in proc.stderr and not (tmp_path / "x").exists()
    alone = sweep(str(spec), "--objective", "edge_m", "--out", str(tmp_path / "y"))
    assert alone.returncode == 2 and "only with --search N" in alone.stderr


def test_a_missing_optuna_names_the_extra(monkeypatch: pytest.MonkeyPatch, spec: Path,
                                          tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                          ) -> None:
    from stairbot.cli import main

    real = builtins.__import__

    def no_optuna(name: str, *args: Any, **kwargs: Any) -> Any:
        if name == "optuna" or name.startswith("optuna."):
            raise ImportError(f"No module named {name!r}")
        return real(name, *args, **kwargs)

    monkeypatch.delitem(sys.modules, "optuna", raising=False)
    monkeypatch.setattr(builtins, "__import__", no_optuna)
    code = main(["sweep", str(spec), "--search", "3", "--out", str(tmp_path / "z")])
    assert code == 2
    err = capsys.readouterr().err
    assert "--search" in err and "pip install 'stairbot[search]'" in err
    assert not (tmp_path / "z").exists()
