"""Hostile input (issue 11, item 5): devices, FIFOs, huge or deeply nested
files, absurd numbers, degenerate robots and stairs, a full disk.  Each is
refused with one line, ``stairbot: error: ...`` naming the offending thing,
and exit 2 (bad input) or 1 (a runtime fault: the disk filled during a run,
after the robot was stopped); never a traceback or a hang.

Cases that hung before the fix run in a subprocess with a timeout; the rest
through ``main(argv)``."""

from __future__ import annotations

import json
import os
import resource
import signal
import subprocess
import sys
from importlib import resources
from pathlib import Path

import pytest

from stairbot.cli import main

ROBOT = resources.files("stairbot.inputs").joinpath("default_robot.toml").read_text("utf-8")
ROOT = Path(__file__).resolve().parents[2]
QUICK = "[stairs]\ncount = 1\n"  # a short run: what a disk can fill during


def one_error_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err
    assert len(lines) == 1, f"expected one line, got: {err!r}"
    assert lines[0].startswith("stairbot: error: ")
    return lines[0]


def robot(old: str, new: str) -> str:
    assert old in ROBOT
    return ROBOT.replace(old, new)


@pytest.fixture(scope="module")
def place(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("hostile")
    os.mkfifo(d / "fifo.toml")
    return d


def materialise(place: Path, argv: list[str]) -> list[str]:
    """``@name=text`` in argv becomes a file ``name`` holding ``text``;
    ``FIFO`` the FIFO; ``@@name`` a path in the folder not yet made."""
    out = []
    for arg in argv:
        if arg == "FIFO":
            arg = str(place / "fifo.toml")
        elif arg.startswith("@@"):
            arg = str(place / arg[2:])
        elif arg.startswith("@"):
            name, _, text = arg[1:].partition("=")
            (place / name).write_text(text, encoding="utf-8")
            arg = str(place / name)
        out.append(arg)
    return out


# -- cases that hung (or ran away with memory) before: a subprocess each -----------

HUNG = {
    "run-scenario-dev-zero": (["run", "--scenario", "/dev/zero"], 2, ["/dev/zero", "device"]),
    "run-config-dev-zero": (["run", "--config", "/dev/zero"], 2, ["/dev/zero", "device"]),
    "run-scenario-dev-urandom": (["run", "--scenario", "/dev/urandom"], 2,
                                 ["/dev/urandom", "regular file"]),
    "run-config-dev-urandom": (["run", "--config", "/dev/urandom"], 2,
                               ["/dev/urandom", "regular file"]),
    "run-scenario-fifo": (["run", "--scenario", "FIFO"], 2, ["fifo.toml", "FIFO"]),
    "run-config-fifo": (["run", "--config", "FIFO"], 2, ["fifo.toml", "FIFO"]),
    "scenario-check-fifo": (["scenario", "check", "FIFO"], 2, ["fifo.toml", "FIFO"]),
    "config-show-dev-zero": (["config", "show", "--config", "/dev/zero"], 2, ["/dev/zero"]),
    "sweep-check-fifo": (["sweep", "check", "FIFO"], 2, ["fifo.toml", "FIFO"]),
    "sweep-check-dev-zero": (["sweep", "check", "/dev/zero"], 2, ["/dev/zero"]),
    "console-scenario-dev-zero": (["console", "--scenario", "/dev/zero"], 2, ["/dev/zero"]),
    "fake-boards-config-dev-zero": (["fake-boards", "--serial", "--config", "/dev/zero"], 2,
                                    ["/dev/zero"]),
    "run-journal-fifo": (["run", "--journal", "FIFO"], 2,
                         ["fifo.toml", "cannot write the journal: a FIFO"]),
    "run-record-fifo": (["run", "--record", "FIFO"], 2,
                        ["fifo.toml", "cannot write the record", "no process reads"]),
    "resume-journal-fifo": (["run", "--resume", "--yes", "--journal", "FIFO"], 2,
                            ["fifo.toml", "FIFO", "journal"]),
    "url-serial-timeout-inf": (["run", "--robot", "serial://loop://?timeout=inf"], 2,
                               ["timeout", "inf", "0 < timeout <= 60"]),
    "url-serial-retries-huge": (["run", "--robot", "serial://loop://?retries=99999999999"], 2,
                                ["retries", "99999999999", "0 to 100"]),
    "url-serial-grace-inf": (["run", "--robot", "serial://loop://?grace=inf"], 2,
                             ["grace", "inf", "0 <= grace <= 60"]),
    "url-can-retries-huge": (["run", "--robot", "can://virtual/x?retries=99999999999"], 2,
                             ["retries", "0 to 100"]),
    "config-lift-too-slow-in-m-s": (["run", "--config", "@c5.toml=" + robot(
        "lift_speed = 10.0", "lift_speed = 0.05")], 2,
        ["motors.lift_speed", "0.0001 m/s", "0.0002 to 1 m/s"]),
    "config-wheel-mass-1e-9": (["run", "--config", "@m.toml=" + robot("wheel = 0.02",
                                                                       "wheel = 1e-9")], 2,
                               ["masses.wheel", ">= 0.001"]),
}


@pytest.mark.parametrize("name", list(HUNG))
def test_what_hung_is_refused_at_once(place: Path, name: str) -> None:
    argv, code, words = HUNG[name]
    proc = subprocess.run([sys.executable, "-m", "stairbot", *materialise(place, argv)],
                          capture_output=True, text=True, timeout=30, cwd=place,
                          stdin=subprocess.DEVNULL,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    line = one_error_line(proc.stderr)
    assert proc.returncode == code, proc.stderr
    for w in words:
        assert w in line


# -- the rest through main(argv) -------------------------------------------------------

NESTED_ARRAYS = "a = " + "[" * 100_000 + "]" * 100_000 + "\n"
NESTED_TABLES = "a = " + "{b=" * 5000 + "1" + "}" * 5000 + "\n"
LONG = "x" * 5000 + ".toml"

REFUSED = {
    # files
    "scenario-nested-arrays": (["run", "--scenario", "@n1.toml=" + NESTED_ARRAYS],
                               ["n1.toml", "nested too deeply"]),
    "config-nested-arrays": (["run", "--config", "@n2.toml=" + NESTED_ARRAYS],
                             ["n2.toml", "nested too deeply"]),
    "scenario-nested-tables": (["run", "--scenario", "@n3.toml=" + NESTED_TABLES],
                               ["n3.toml", "nested too deeply"]),
    "sweep-check-nested": (["sweep", "check", "@n4.toml=" + NESTED_ARRAYS],
                           ["n4.toml", "nested too deeply"]),
    "scenario-long-file-name": (["run", "--scenario", "@@" + LONG],
                                ["xxx.toml (a path of", "File name too long"]),
    "config-long-file-name": (["run", "--config", "@@" + LONG],
                              ["xxx.toml (a path of", "File name too long"]),
    "scenario-long-plain-name": (["run", "--scenario", "y" * 5000],
                                 ["(a path of 5000 characters)", "no such file"]),
    "scenario-over-1-MiB": (["scenario", "check", "@big.toml=" + "# padding\n" * 120_000],
                            ["big.toml", "1200000 bytes", "at most 1048576 bytes"]),
    # robot URLs
    "url-serial-time-scale-inf": (["run", "--robot", "serial://loop://?time_scale=inf"],
                                  ["time_scale", "inf", "0.01 to 1000"]),
    "url-serial-time-scale-nan": (["run", "--robot", "serial://loop://?time_scale=nan"],
                                  ["time_scale", "nan", "0.01 to 1000"]),
    "url-serial-time-scale-1e308": (["run", "--robot", "serial://loop://?time_scale=1e308"],
                                    ["time_scale", "1e308", "0.01 to 1000"]),
    "url-serial-bad-percent": (["run", "--robot", "serial://loop://?a=%ff"],
                               ["serial://loop://?a=%ff", "percent-encoding"]),
    "url-serial-baud-huge": (["run", "--robot", "serial://loop://?baud=1000000000000"],
                             ["baud", "20000000"]),
    "url-serial-watchdog-huge": (["run", "--robot", "serial://loop://?watchdog=1000000000"],
                                 ["watchdog", "65535"]),
    "url-can-time-scale-1e308": (["run", "--robot", "can://virtual/x?time_scale=1e308"],
                                 ["time_scale", "1e308", "0.01 to 1000"]),
    "url-can-time-scale-nan": (["run", "--robot", "can://virtual/x?time_scale=nan"],
                               ["time_scale", "nan"]),
    "url-can-bad-percent": (["run", "--robot", "can://virtual/x?a=%ff"],
                            ["percent-encoding"]),
    # scenarios
    "scenario-tread-5e-324": (["run", "--scenario", "@t1.toml=[stairs]\ntread = 5e-324\n"],
                              ["t1.toml", "stairs.tread", ">= 0.01 and <= 10"]),
    "scenario-rise-5e-324": (["run", "--scenario", "@t2.toml=[stairs]\nrise = 5e-324\n"],
                             ["t2.toml", "stairs.rise", ">= 0.005 and <= 1"]),
    "scenario-steps-tread-5e-324": (
        ["run", "--scenario", "@t3.toml=[stairs]\nsteps = [{rise = 0.17, tread = 5e-324}]\n"],
        ["t3.toml", "stairs.steps[0].tread", ">= 0.01"]),
    "scenario-rise-1e300": (["run", "--scenario", "@t4.toml=[stairs]\nrise = 1e300\n"],
                            ["stairs.rise", "<= 1"]),
    "scenario-width-1e300": (["run", "--scenario", "@t5.toml=[stairs]\nwidth = 1e300\n"],
                             ["stairs.width", "<= 20"]),
    "scenario-noise-1e300": (["run", "--scenario", "@t6.toml=[sensors]\nnoise = 1e300\n"],
                             ["sensors.noise", "<= 1"]),
    "scenario-fault-at-1e300": (
        ["run", "--scenario",
         "@t7.toml=[[faults]]\nat = 1e300\nsensor = 'SFL'\nkind = 'error'\n"],
        ["faults[0].at", "<= 86400"]),
    # robot configs
    "config-mass-1e-300": (["run", "--config", "@c1.toml=" + robot(
        "first_module = 0.55", "first_module = 1e-300")], ["c1.toml", "masses.first_module",
                                                             ">= 0.001 and <= 1000"]),
    "config-mass-1e9": (["run", "--config", "@c2.toml=" + robot(
        "second_module = 1.3", "second_module = 1e9")], ["masses.second_module", "<= 1000"]),
    "config-lift-speed-1e-300": (["run", "--config", "@c3.toml=" + robot(
        "lift_speed = 10.0", "lift_speed = 1e-300")], ["motors.lift_speed", ">= 0.01"]),
    "config-lift-speed-1e300": (["run", "--config", "@c4.toml=" + robot(
        "lift_speed = 10.0", "lift_speed = 1e300")], ["motors.lift_speed", "<= 1000"]),
    "config-wheel-speed-1e300": (["run", "--config", "@c6.toml=" + robot(
        "wheel_speed = 1.0", "wheel_speed = 1e300")], ["motors.wheel_speed", "<= 1000"]),
    "config-wheel-too-fast-in-m-s": (["run", "--config", "@c7.toml=" + robot(
        "wheel_speed = 1.0", "wheel_speed = 100.0")], ["motors.wheel_speed", "10.1 m/s",
                                                       "0.001 to 5 m/s"]),
    "config-wheel-torque-1e300": (["run", "--config", "@c8.toml=" + robot(
        "wheel_torque = 0.6", "wheel_torque = 1e300")], ["motors.wheel_torque", "<= 10000"]),
    "config-track-width-1e300": (["run", "--config", "@c9.toml=" + robot(
        "track_width = 0.16", "track_width = 1e300")], ["geometry.track_width", "<= 10"]),
    "config-show-segment-height-1e-300": (["config", "show", "--config", "@c10.toml=" + robot(
        "segment_height = 0.045", "segment_height = 1e-300")],
        ["geometry.segment_height", ">= 0.001"]),
}


@pytest.mark.parametrize("name", list(REFUSED))
def test_bad_input_is_refused_with_one_line(place: Path, name: str,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    argv, words = REFUSED[name]
    assert main(materialise(place, argv)) == 2
    line = one_error_line(capsys.readouterr().err)
    assert len(line) < 1000  # a long path is shortened
    for w in words:
        assert w in line


@pytest.mark.parametrize("value", ["1e-300", "inf", "nan", "1e308", "-1"])
def test_time_scale_is_finite_and_bounded(value: str,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    """argparse's own form: the usage, then one line naming the option."""
    with pytest.raises(SystemExit) as info:
        main(["run", "--time-scale", value])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    last = err.strip().splitlines()[-1]
    assert last.startswith("stairbot run: error: argument --time-scale: ")
    assert f"{value!r} is out of range; allowed: 0.01 to 1000" in last


# -- writes: a full disk ---------------------------------------------------------------


def test_record_on_dev_full_stops_the_run(place: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    journal = place / "dev-full.jsonl"
    argv = ["run", "-q", "--scenario", "@q.toml=" + QUICK, "--record", "/dev/full",
            "--journal", str(journal)]
    assert main(materialise(place, argv)) == 1
    line = one_error_line(capsys.readouterr().err)
    assert "/dev/full: cannot write the record: No space left on device" in line
    assert "every motor stopped" in line
    end = json.loads(journal.read_text().splitlines()[-1])
    assert end["kind"] == "end" and end["outcome"] == "error"
    assert "cannot write the record" in end["error"]


def test_journal_on_a_device_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "--journal", "/dev/full"]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert "/dev/full: cannot write the journal: a character device" in line




@pytest.mark.parametrize("full", ["record", "journal"])
def test_disk_full_mid_run_stops_the_robot(place: Path, full: str, disk_fills: dict[str, int],
                                           capsys: pytest.CaptureFixture[str]) -> None:
    record, journal = place / f"{full}-r.jsonl", place / f"{full}-j.jsonl"
    disk_fills[(record if full == "record" else journal).name] = 40
    argv = ["run", "-q", "--scenario", "@q.toml=" + QUICK, "--record", str(record),
            "--journal", str(journal)]
    assert main(materialise(place, argv)) == 1
    line = one_error_line(capsys.readouterr().err)
    assert f"{full}-{full[0]}.jsonl: cannot write the {full}: No space left on device" in line
    assert "the run stopped" in line
    kept = (record if full == "record" else journal).read_text().splitlines()
    assert len(kept) == 40 and all(json.loads(k) for k in kept)  # whole lines, kept
    other = journal if full == "record" else record
    last = json.loads(other.read_text().splitlines()[-1])
    if full == "record":  # the journal says how the run ended: an error, the robot stopped
        assert last["kind"] == "end" and last["outcome"] == "error"
        assert f"cannot write the {full}" in last["error"]
    else:  # the record's summary says so
        assert last["kind"] == "summary" and "cannot write the journal" in json.dumps(last)


def _file_limit() -> None:
    resource.setrlimit(resource.RLIMIT_FSIZE, (4_000, 4_000))
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)


def test_a_file_size_limit_mid_run_in_a_real_process(place: Path) -> None:
    """The kernel refuses the write (EFBIG past RLIMIT_FSIZE): the same one line."""
    record = place / "limited.jsonl"
    argv = ["run", "-q", "--scenario", "@q.toml=" + QUICK, "--record", str(record)]
    proc = subprocess.run([sys.executable, "-m", "stairbot", *materialise(place, argv)],
                          capture_output=True, text=True, timeout=60, cwd=place,
                          preexec_fn=_file_limit, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert proc.returncode == 1, proc.stderr
    line = one_error_line(proc.stderr)
    assert "limited.jsonl: cannot write the record: File too large" in line
    assert 0 < record.stat().st_size <= 4_000
