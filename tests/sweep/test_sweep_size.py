"""How many cases a spec makes is counted from its axes, before any is built:
a spec over MAX_CASES is refused with one line (exit 2), and ``--limit N``
builds only the cases it runs."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

from stairbot.cli import main
from stairbot.sweep import cases as cases_module
from stairbot.sweep import execute
from stairbot.sweep.cases import Case, check_spec
from stairbot.sweep.spec import MAX_CASES, SpecError, parse_spec

# 1001 x 1001 grid points, 1000 samples each: a billion cases, days only to build
HUGE_SAMPLED = """
[sweep]
cases = 1000
[axes]
"stairs.rise" = { range = [0.10, 0.20, 0.0001] }
"stairs.tread" = { range = [0.20, 0.30, 0.0001] }
"start.yaw_deg" = { uniform = [-5, 5] }
"""
HUGE_GRID = """
[axes]
"stairs.rise" = { range = [0.10, 0.20, 0.0001] }
"stairs.tread" = { range = [0.20, 0.30, 0.0001] }
"""
# 3 x 4 grid points, 5 samples each
SMALL = """
[sweep]
cases = 5
[axes]
"stairs.rise" = [0.15, 0.16, 0.17]
"stairs.tread" = [0.26, 0.28, 0.30, 0.32]
"start.yaw_deg" = { uniform = [-5, 5] }
"""


def no_building(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Make building any case fail the test; returns the indices asked for."""
    asked: list[int] = []

    def refuse(spec: Any, index: int, override: Any = None) -> Case:
        asked.append(index)
        raise AssertionError(f"case {index} was built")

    monkeypatch.setattr(cases_module, "build_case", refuse)
    return asked


def counting(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Count the cases built (edge checks aside); returns their indices."""
    built: list[int] = []
    real = cases_module.build_case

    def build(spec: Any, index: int, override: Any = None) -> Case:
        if override is None:
            built.append(index)
        return real(spec, index, override)

    monkeypatch.setattr(cases_module, "build_case", build)
    return built


@pytest.mark.parametrize(("text", "field", "words"), [
    (HUGE_SAMPLED, "axes, sweep.cases",
     "1002001 grid point(s) x 1000 case(s) each = 1002001000 cases"),
    (HUGE_GRID, "axes", "1002001 grid points"),
], ids=["sampled", "grid"])
@pytest.mark.parametrize("how", [["check"], ["--limit", "1"]], ids=["check", "limit"])
def test_a_spec_over_the_case_limit_is_refused_before_any_case_is_built(
        text: str, field: str, words: str, how: list[str], tmp_path: Path,
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    asked = no_building(monkeypatch)
    spec = tmp_path / "big.toml"
    spec.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    argv = ["sweep", "check", str(spec)] if how == ["check"] else \
        ["sweep", str(spec), *how, "--out", str(out), "-j", "1", "-q"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"stairbot: error: {spec}: {field}: {words}; allowed: at most "
                   f"{MAX_CASES} cases in a sweep (fewer grid values, or fewer samples "
                   "per point)"]
    assert asked == [] and not out.exists()


def test_the_limit_is_the_count_of_cases_not_of_grid_points() -> None:
    # 20 x 5000 values = 100,000 grid points: at the limit, not over it
    at = parse_spec('[axes]\n"stairs.count" = { range = [1, 20, 1] }\n'
                    '"sensors.seed" = { range = [1, 5000, 1] }\n', "at.toml")
    assert at.total == MAX_CASES
    with pytest.raises(SpecError, match=r"axes, sweep.cases: 100000 grid point\(s\) x 2 "):
        parse_spec('[sweep]\ncases = 2\n[axes]\n"stairs.count" = { range = [1, 20, 1] }\n'
                   '"sensors.seed" = { range = [1, 5000, 1] }\n'
                   '"start.yaw_deg" = { uniform = [-1, 1] }\n', "over.toml")


def test_check_with_a_limit_builds_only_the_first_cases(monkeypatch: pytest.MonkeyPatch) -> None:
    built = counting(monkeypatch)
    spec = parse_spec(SMALL, "small.toml")
    assert spec.total == 60
    assert [c.index for c in check_spec(spec, 2)] == [0, 1]
    assert built == [0, 1]


def test_sweep_with_limit_1_builds_and_runs_one_case(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    built = counting(monkeypatch)
    ran: list[int] = []

    @contextmanager
    def no_pool(jobs: int, dask: str | None = None) -> Iterator[tuple[Any, str]]:
        yield None, "no pool"

    def run_cases(cases: list[Case], *_: Any) -> execute.Outcome:
        ran.extend(c.index for c in cases)
        return execute.Outcome()

    monkeypatch.setattr(execute, "open_executor", no_pool)
    monkeypatch.setattr(execute, "run_cases", run_cases)
    spec = tmp_path / "small.toml"
    spec.write_text(SMALL, encoding="utf-8")
    assert main(["sweep", str(spec), "--limit", "1", "--out", str(tmp_path / "out"),
                 "-q", "--no-png"]) == 0
    assert built == [0] and ran == [0]


def test_a_range_too_fine_to_count_is_refused_with_one_line() -> None:
    with pytest.raises(SpecError, match=r"x\.toml: axes\.stairs\.rise\.range: \[0, 1e\+300, "
                       r"1e-300\] gives more than 100000 values; allowed: at most 100000"):
        parse_spec('[axes]\n"stairs.rise" = { range = [0, 1e300, 1e-300] }\n', "x.toml")
