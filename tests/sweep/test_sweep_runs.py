"""Whole sweeps on the simulated robot: the CI spec end to end, a failing
case reproduced by `stairbot run`, SIGKILL and Ctrl-C then --resume, and the
Dask executor on a LocalCluster."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Any

import pytest

from stairbot.sweep.verdict import PASSING, VERDICTS, judge

ROOT = Path(__file__).parents[2]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


def sweep(*args: str, timeout: float = 600) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "stairbot", "sweep", *args], cwd=ROOT,
                          env=ENV, capture_output=True, text=True, timeout=timeout)


def lines(folder: Path) -> list[dict[str, Any]]:
    text = (folder / "cases.jsonl").read_text("utf-8")
    return [json.loads(x) for x in text.splitlines()]


def test_quick_spec_end_to_end(tmp_path: Path) -> None:
    out = tmp_path / "quick"
    proc = sweep("sweeps/quick.toml", "-j", "2", "--out", str(out), "-q")
    records = lines(out)
    assert sorted(r["case"] for r in records) == list(range(48))
    counts = Counter(r["verdict"] for r in records)
    assert set(counts) <= set(VERDICTS) and "error" not in counts, counts
    failing = [r for r in records if r["verdict"] not in PASSING]
    # exit 1 exactly when some case fails; the counts are on the last line
    assert proc.returncode == (1 if failing else 0), proc.stderr
    last = proc.stdout.strip().splitlines()[-1]
    assert all(f"{v} {counts.get(v, 0)}" in last for v in VERDICTS), last
    for r in records:
        assert r["result"] is not None and r["wall_s"] > 0
        assert r["facts"]["zone"] in ("inside", "band", "outside")
        margins = r["result"]["margins"]  # each case's least margins (docs/envelope.md)
        assert margins["stability_m"] is not None and margins["stroke_m"] is not None
        assert (margins["edge_m"] is None) == (r["result"]["steps_climbed"] == 0)
        if r["verdict"] in PASSING:
            assert "reproduce" not in r
        else:
            assert (out / "failures" / f"case-{r['case']:06d}.toml").is_file()
    # inside the limits and with no fault, refusing is wrong, never passing
    assert not [r for r in records if r["facts"]["zone"] == "inside"
                and r["verdict"] == "refused"]
    rep = subprocess.run([sys.executable, "-m", "stairbot", "sweep", "report", str(out),
                          "--png", str(tmp_path / "map.png")], cwd=ROOT, env=ENV,
                         capture_output=True, text=True, timeout=120)
    assert rep.returncode == proc.returncode, rep.stderr
    assert "stairs.rise" in rep.stdout and (tmp_path / "map.png").stat().st_size > 10_000


# SBR and SBL fail for good half way up the step, so every case ends
# "stranded" (by design: with no back sensor left nothing finds the edge
# below, and the robot cannot limp home; it stops there, lifts holding) --
# with a robot config override, to write both files.
STRANDED = """
[sweep]
name = "stranded"
cases = 2
seed = 5
[axes]
"stairs.count" = 1
"config.masses.second_module" = { uniform = [1.2, 1.4] }
"sensors.seed" = { randint = [1, 1000] }
"faults" = [[{ at = 30.0, sensor = "SBR", kind = "error" },
             { at = 30.0, sensor = "SBL", kind = "error" }]]
"""


def test_a_failing_case_reproduces_its_verdict_with_stairbot_run(tmp_path: Path) -> None:
    spec = tmp_path / "stranded.toml"
    spec.write_text(STRANDED, encoding="utf-8")
    out = tmp_path / "out"
    proc = sweep(str(spec), "-j", "2", "--out", str(out), "-q")
    assert proc.returncode == 1, proc.stderr
    for rec in lines(out):
        assert rec["verdict"] == "stranded", rec
        scen = out / "failures" / f"case-{rec['case']:06d}.toml"
        robot = out / "failures" / f"case-{rec['case']:06d}.robot.toml"
        assert rec["reproduce"].startswith("stairbot run --yes --scenario "), rec
        run = subprocess.run([sys.executable, "-m", "stairbot", "run", "--yes", "--scenario",
                              str(scen), "--config", str(robot), "--json", "-q"], cwd=ROOT,
                             env=ENV,
                             capture_output=True, text=True, timeout=120)
        got = json.loads(run.stdout)
        assert judge(got, rec["facts"])[0] == rec["verdict"]
        for key in ("outcome", "steps_climbed", "steps_descended", "final_offset_m",
                    "max_pitch_deg", "sim_time_s", "ascent_end", "error"):
            assert got[key] == rec["result"][key], key  # the very same run
        assert run.returncode == 1  # its [expect] says climbed and home


N_RESUMABLE = 30
RESUMABLE = f"""
[sweep]
name = "resumable"
cases = {N_RESUMABLE}
seed = 11
[axes]
"stairs.count" = 2
"sensors.seed" = {{ randint = [1, 1000000] }}
"""


def _as_from_a_terminal() -> None:
    # Ctrl-C's default, as a terminal's shell gives it: a test run started in
    # the background (`pytest ... &` in a script) inherits SIGINT ignored, and
    # Python then never raises KeyboardInterrupt: the sweep ran to the end
    # and exited 0.
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _start(spec: Path, out: Path, *extra: str) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "stairbot", "sweep", str(spec), "-j", "2",
                             "--out", str(out), "-q", "--no-png", *extra], cwd=ROOT, env=ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=_as_from_a_terminal)


def _wait_for_lines(out: Path, n: int, proc: subprocess.Popen[str]) -> None:
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and proc.poll() is None:
        path = out / "cases.jsonl"
        if path.exists() and path.read_text("utf-8").count("\n") >= n:
            return
        time.sleep(0.05)
    pytest.fail("the sweep wrote too few cases")


@pytest.mark.parametrize("how", ["SIGKILL", "Ctrl-C"])
def test_stop_halfway_then_resume_loses_no_case_and_runs_none_twice(how: str,
                                                                    tmp_path: Path) -> None:
    spec = tmp_path / "r.toml"
    spec.write_text(RESUMABLE, encoding="utf-8")
    out = tmp_path / "out"
    proc = _start(spec, out)
    _wait_for_lines(out, 5, proc)
    if how == "SIGKILL":  # the whole group: the sweep and its pool
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(timeout=60)
        with (out / "cases.jsonl").open("a", encoding="utf-8") as f:
            f.write('{"case": 13, "verd')  # as if killed mid-write
    else:  # as a terminal's Ctrl-C does: to the whole group, the pool's workers too
        os.killpg(proc.pid, signal.SIGINT)
        assert proc.wait(timeout=120) == 130, proc.stderr.read() if proc.stderr else ""
    first = {r["case"] for r in lines_complete(out)}
    # 25 cases of two steps are left when the signal is sent, some 10 s of work:
    # with 14 one-step cases a loaded CI machine let the sweep finish them
    # all before the test's Ctrl-C (exit 0)
    assert 5 <= len(first) < N_RESUMABLE
    again = sweep(str(spec), "-j", "2", "--out", str(out), "--resume", "-q", "--no-png")
    assert again.returncode == 0, again.stderr
    cases = [r["case"] for r in lines(out)]
    assert sorted(cases) == list(range(N_RESUMABLE)), cases  # each exactly once
    assert f"{N_RESUMABLE - len(first)} run now" in again.stdout
    # without --resume a folder with cases is refused, one line, exit 2
    refused = sweep(str(spec), "--out", str(out), "-q")
    assert refused.returncode == 2 and "--resume" in refused.stderr


def lines_complete(folder: Path) -> list[dict[str, Any]]:
    text = (folder / "cases.jsonl").read_text("utf-8")
    return [json.loads(x) for x in text.splitlines(keepends=True) if x.endswith("\n")]


def test_dask_local_cluster_runs_the_same_cases(tmp_path: Path) -> None:
    pytest.importorskip("distributed", reason="the Dask executor needs stairbot[dask]")
    spec = tmp_path / "r.toml"
    spec.write_text(RESUMABLE.replace(f"cases = {N_RESUMABLE}", "cases = 3"), encoding="utf-8")
    local = sweep(str(spec), "-j", "1", "--out", str(tmp_path / "local"), "-q", "--no-png")
    dask = sweep(str(spec), "-j", "2", "--dask", "local", "--out", str(tmp_path / "dask"),
                 "-q", "--no-png")
    assert dask.returncode == local.returncode == 0, dask.stderr
    strip = ("wall_s", "wall_time_s", "realtime_factor")

    def key(rec: dict[str, Any]) -> str:
        res = {k: v for k, v in rec["result"].items() if k not in strip}
        return json.dumps([rec["case"], rec["axes"], rec["verdict"], res], sort_keys=True)
    assert sorted(map(key, lines(tmp_path / "local"))) == sorted(
        map(key, lines(tmp_path / "dask")))
