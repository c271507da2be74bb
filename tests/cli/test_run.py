"""`stairbot run` end to end: progress lines, the summary, --json, --record,
exit codes against [expect], --calibrate-only, Ctrl-C."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from importlib import resources
from pathlib import Path

import lost_sensor
import pytest

from stairbot.cli import main
from stairbot.cli.run import _ctrl_c_stops

RESULT_KEYS = {"outcome", "ascent_end", "steps_climbed", "steps_descended", "pauses", "error",
               "fell", "max_pitch_deg", "final_offset_m", "sim_time_s", "wall_time_s",
               "realtime_factor"}


def console_script() -> list[str]:
    exe = shutil.which("stairbot", path=str(Path(sys.executable).parent))
    return [exe] if exe else [sys.executable, "-m", "stairbot"]


def test_json_prints_one_object_and_progress_goes_to_stderr(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "--json", "--scenario", "step_too_high"]) == 0
    out, err = capsys.readouterr()
    data = json.loads(out)  # one object, nothing else on stdout
    assert RESULT_KEYS <= set(data)
    assert data["outcome"] == "completed" and data["ascent_end"] == "obstacle"
    assert data["as_expected"] is True and data["mismatches"] == []
    assert data["scenario"] == "step_too_high" and data["robot"] == "sim://"
    assert "ascent 3" in err  # the phase lines went to stderr


def test_json_holds_the_run_s_margins(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "--json", "-q", "--scenario", "step_too_high"]) == 0
    data = json.loads(capsys.readouterr().out)
    margins = data["margins"]
    assert set(margins) == {"stability_m", "pitch_deg", "edge_m", "stroke_m", "sensor_holds"}
    # it squared up to the riser and turned on its middle wheels, the ends lifted
    assert 0.0 < margins["stability_m"] < 0.05
    assert margins["pitch_deg"] == pytest.approx(15.0 - data["max_pitch_deg"], abs=0.01)
    assert margins["edge_m"] is None  # it never stood on a tread
    assert 0.0 <= margins["stroke_m"] < 0.2
    assert margins["sensor_holds"] == 0


def test_text_mode_prints_phase_lines_then_a_summary(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "--scenario", "step_too_high"]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert lines[0].startswith("running step_too_high (A 0.25 m rise")
    assert any("phase" in line and "calibration" in line for line in lines)
    summary = out[out.index("summary (step_too_high on sim://)"):]
    assert "outcome           completed (ascent ended: obstacle)" in summary
    assert "  least margins     stability " in summary and "sensor holds 0" in summary
    assert "expected          yes" in summary


def test_record_writes_the_event_stream(tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    record = tmp_path / "events.jsonl"
    assert main(["run", "-q", "--scenario", "calibration_case1_open_floor",
                 "--record", str(record)]) == 0
    events = [json.loads(line) for line in record.read_text().splitlines()]
    assert events, "nothing recorded"
    assert {"time_s", "kind", "phase", "message", "data"} <= set(events[0])
    assert [e["kind"] for e in events[-2:]] == ["end", "summary"]
    assert events[-1]["data"]["outcome"] == "stopped"
    assert events[-2]["data"]["outcome"] == "stopped"
    assert [e["time_s"] for e in events] == sorted(e["time_s"] for e in events)
    out = capsys.readouterr().out
    assert "phase" not in out.split("summary")[0]  # -q: no progress lines


def test_a_run_that_differs_from_expect_exits_1_naming_the_field(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    p = tmp_path / "wrong.toml"
    p.write_text("[stairs]\ncount = 0\n[expect]\noutcome = 'stopped'\nsteps_climbed = 3\n")
    assert main(["run", "--json", "--scenario", str(p)]) == 1
    out, err = capsys.readouterr()
    assert json.loads(out)["mismatches"] == ["steps_climbed: expected 3, got 0"]
    assert "steps_climbed: expected 3, got 0" in err.splitlines()[-1]


def test_without_expect_a_run_must_complete(tmp_path: Path) -> None:
    p = tmp_path / "open.toml"
    p.write_text("[stairs]\ncount = 0\n")  # open floor ends "stopped", not "completed"
    assert main(["run", "-q", "--scenario", str(p)]) == 1


def test_calibrate_only_squares_up_and_stops(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "--json", "--calibrate-only", "--scenario",
                 "calibration_case2_yaw_left"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["outcome"] == "completed"
    assert data["steps_climbed"] == 0 and data["ascent_end"] is None


def test_the_console_script_runs_the_default_job(tmp_path: Path) -> None:
    proc = subprocess.run([*console_script(), "run", "--json"], capture_output=True,
                          text=True, cwd=tmp_path, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    data = json.loads(proc.stdout)
    assert (data["outcome"], data["ascent_end"], data["steps_climbed"],
            data["steps_descended"]) == ("completed", "top_reached", 5, 5)


def test_ctrl_c_stops_the_robot_and_exits_130(tmp_path: Path) -> None:
    proc = subprocess.Popen([*console_script(), "run", "--realtime"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    assert proc.stdout is not None
    assert proc.stdout.readline().startswith("running default")
    assert "phase" in proc.stdout.readline()  # the run has started
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert "interrupted" in err and "emergency stop latched" in err
    assert "outcome           stopped" in out
    assert "Traceback" not in err


def test_ctrl_c_latches_the_emergency_stop_from_a_thread_of_its_own() -> None:
    """The first Ctrl-C calls the robot's estop() at once, from another thread
    (it must not wait for the run loop's read), and asks the loop to stop."""
    stopped: list[tuple[str, str]] = []
    estopped = threading.Event()
    reasons: list[str] = []

    def estop() -> None:
        stopped.append(("estop", threading.current_thread().name))
        estopped.set()

    with _ctrl_c_stops(reasons.append, estop):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.01)  # the handler runs between bytecodes
        assert estopped.wait(5)
    assert stopped == [("estop", "Ctrl-C emergency stop")]
    assert reasons == ["interrupted by Ctrl-C: emergency stop latched"]


def test_record_to_an_existing_file_never_overwrites_it(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 12 item 5, "it loses recordings": `--record` to a file that exists
    writes beside it and says so."""
    record = tmp_path / "events.jsonl"
    record.write_text("an earlier recording\n")
    assert main(["run", "-q", "--scenario", "calibration_case1_open_floor",
                 "--record", str(record)]) == 0
    assert record.read_text() == "an earlier recording\n"
    beside = tmp_path / "events-1.jsonl"
    assert json.loads(beside.read_text().splitlines()[-1])["kind"] == "summary"
    err = capsys.readouterr().err
    assert f"{record} exists (not overwritten): recording to {beside}" in err


def test_a_shipped_landing_scenario_runs_on_the_robot_it_names(
        capsys: pytest.CaptureFixture[str]) -> None:
    """landing_wall says robot = "landings" (the side pair): without --config
    the run is on that robot and ends as its [expect] says."""
    assert main(["run", "--json", "-q", "--scenario", "landing_wall"]) == 0
    out, err = capsys.readouterr()
    data = json.loads(out)
    assert data["config"] == "<robot landings>" and data["as_expected"] is True
    assert data["ascent_end"] == "landing_closed"
    assert "note" not in err


def test_the_summary_names_the_robot_as_a_person_reads_it(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scenario = tmp_path / "open.toml"
    scenario.write_text("[stairs]\ncount = 0\n[expect]\noutcome = 'stopped'\n")
    for given, shown in (([], "reference (shipped)"), (["--config", "ir"], "ir (shipped)")):
        assert main(["run", "-q", "--scenario", str(scenario), *given]) == 0
        assert f"  robot config      {shown}\n" in capsys.readouterr().out


OPEN_FLOOR_FOR = "robot = {robot!r}\n[stairs]\ncount = 0\n[expect]\noutcome = 'stopped'\n"


def test_a_scenario_robot_path_is_read_beside_the_scenario(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "robots").mkdir()
    ideal = resources.files("stairbot.inputs").joinpath("configs", "ideal.toml")
    (tmp_path / "robots" / "mine.toml").write_text(ideal.read_text("utf-8"))
    scenario = tmp_path / "open.toml"
    scenario.write_text(OPEN_FLOOR_FOR.format(robot="robots/mine.toml"))
    assert main(["run", "--json", "-q", "--scenario", str(scenario)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["config"] == str(tmp_path / "robots" / "mine.toml")


def test_config_overrides_the_scenario_robot_with_a_note(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scenario = tmp_path / "open.toml"
    scenario.write_text(OPEN_FLOOR_FOR.format(robot="ideal"))
    assert main(["run", "--json", "-q", "--scenario", str(scenario),
                 "--config", "reference"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["config"] == "<default default_robot.toml>"
    notes = [line for line in err.splitlines() if "note" in line]
    assert notes == ["stairbot: note: --config reference overrides the robot open is "
                     "written for (ideal): its [expect] may not hold"]
    # the same robot by --config: nothing to note
    assert main(["run", "--json", "-q", "--scenario", str(scenario), "--config", "ideal"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["config"] == "<robot ideal>" and "note" not in err


LOST_MID_CLIMB = lost_sensor.LOST_MID_CLIMB + """
[expect]
outcome = "came_home_degraded"
steps_climbed = 1
steps_descended = 1
max_final_offset_m = 0.05
"""


def test_yes_lets_the_robot_limp_home_on_a_sensor_lost_mid_climb(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scenario = tmp_path / "lost.toml"
    scenario.write_text(LOST_MID_CLIMB, "utf-8")
    assert main(["run", "--yes", "--json", "--scenario", str(scenario)]) == 0
    out, err = capsys.readouterr()
    data = json.loads(out)
    assert (data["outcome"], data["ascent_end"]) == ("came_home_degraded", "sensor_lost")
    assert "degraded stop: SFR" in err and "limp home (consented)" in err
    assert main(["run", "--json", "--scenario", str(scenario)]) == 1
    out, err = capsys.readouterr()
    data = json.loads(out)
    assert (data["outcome"], data["awaits_consent"]) == ("error", True), data
    assert "degraded stop: SFR" in err
    # a simulated robot ends with its run: the consent is given before one,
    # never by a resume the simulation would refuse
    assert "`stairbot run --yes` consents before a run" in err and "--resume" not in err
