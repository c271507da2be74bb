"""Probe: run hostile inputs through `python -m stairbot` (whatever PYTHONPATH
finds); report exit, stderr lines, traceback or hang per case.

    python scripts/hostile_inputs.py [name-filter...]

A case is ok when it exits 1 or 2 within 25 s with one non-empty stderr line,
`stairbot: error: ...` (a refusal, not a run that ended otherwise), and no
traceback.  Issue 11, item 5; the tests are
tests/cli/test_hostile_input.py."""

# ruff: noqa: E501  (one case a line)
import importlib.resources as r
import os
import pathlib
import resource
import signal
import subprocess
import sys
import tempfile

EXE = [sys.executable, "-m", "stairbot"]
d = pathlib.Path(tempfile.mkdtemp(prefix="hostile-"))
ROBOT = r.files("stairbot.inputs").joinpath("default_robot.toml").read_text()


def w(name: str, text: str) -> str:
    p = d / name
    p.write_text(text)
    return str(p)


fifo = d / "fifo.toml"
os.mkfifo(fifo)
nested = "a = " + "[" * 100000 + "]" * 100000 + "\n"
nested2 = "a = " + "{b=" * 5000 + "1" + "}" * 5000 + "\n"
longname = str(d / ("x" * 5000 + ".toml"))
cases = {
 "scen /dev/zero": ["run", "--scenario", "/dev/zero"],
 "conf /dev/zero": ["run", "--config", "/dev/zero"],
 "scen /dev/urandom": ["run", "--scenario", "/dev/urandom"],
 "conf /dev/urandom": ["run", "--config", "/dev/urandom"],
 "scen fifo": ["run", "--scenario", str(fifo)],
 "conf fifo": ["run", "--config", str(fifo)],
 "check fifo": ["scenario", "check", str(fifo)],
 "show /dev/zero": ["config", "show", "--config", "/dev/zero"],
 "scen nested": ["run", "--scenario", w("n.toml", nested)],
 "conf nested": ["run", "--config", w("n2.toml", nested)],
 "scen nested2": ["run", "--scenario", w("n3.toml", nested2)],
 "scen longname": ["run", "--scenario", longname],
 "conf longname": ["run", "--config", longname],
 "time-scale 1e-300": ["run", "--time-scale", "1e-300"],
 "time-scale inf": ["run", "--time-scale", "inf"],
 "time-scale nan": ["run", "--time-scale", "nan"],
 "time-scale 1e308": ["run", "--time-scale", "1e308"],
 "url time_scale=inf": ["run", "--robot", "serial://loop://?time_scale=inf"],
 "url time_scale=nan": ["run", "--robot", "serial://loop://?time_scale=nan"],
 "url time_scale=1e308": ["run", "--robot", "serial://loop://?time_scale=1e308"],
 "url timeout=inf": ["run", "--robot", "serial://loop://?timeout=inf"],
 "url retries=huge": ["run", "--robot", "serial://loop://?retries=99999999999"],
 "url a=%ff": ["run", "--robot", "serial://loop://?a=%ff"],
 "can timeout=inf": ["run", "--robot", "can://virtual/x?timeout=inf"],
 "can time_scale=1e308": ["run", "--robot", "can://virtual/x?time_scale=1e308"],
 "record /dev/full": ["run", "--record", "/dev/full"],
 "journal /dev/full": ["run", "--journal", "/dev/full"],
 "tread 5e-324": ["run", "--scenario", w("t.toml", "[stairs]\ntread = 5e-324\n")],
 "rise 5e-324": ["run", "--scenario", w("t2.toml", "[stairs]\nrise = 5e-324\n")],
 "mass 1e-300": ["run", "--config", w("m.toml", ROBOT.replace("first_module = 0.55", "first_module = 1e-300"))],
 "wheel mass 1e-9": ["run", "--config", w("m2.toml", ROBOT.replace("wheel = 0.02", "wheel = 1e-9"))],
 "mass 1e9": ["run", "--config", w("m3.toml", ROBOT.replace("second_module = 1.3", "second_module = 1e9"))],
 "lift_speed 1e-300": ["run", "--config", w("l.toml", ROBOT.replace("lift_speed = 10.0", "lift_speed = 1e-300"))],
 "lift_speed 1e300": ["run", "--config", w("l2.toml", ROBOT.replace("lift_speed = 10.0", "lift_speed = 1e300"))],
 "wheel_speed 1e-300": ["run", "--config", w("l3.toml", ROBOT.replace("wheel_speed = 1.0", "wheel_speed = 1e-300"))],
 "wheel_speed 1e300": ["run", "--config", w("l4.toml", ROBOT.replace("wheel_speed = 1.0", "wheel_speed = 1e300"))],
 "lift_force 1e-300": ["run", "--config", w("l5.toml", ROBOT.replace("lift_force = 120.0", "lift_force = 1e-300"))],
 "wheel_torque 1e300": ["run", "--config", w("l6.toml", ROBOT.replace("wheel_torque = 0.6", "wheel_torque = 1e300"))],
 "segment_height 1e-300": ["run", "--config", w("g1.toml", ROBOT.replace("segment_height = 0.045", "segment_height = 1e-300"))],
 "track_width 1e300": ["run", "--config", w("g2.toml", ROBOT.replace("track_width = 0.16", "track_width = 1e300"))],
 "lift_travel_per_turn 1e-300": ["run", "--config", w("g3.toml", ROBOT.replace("lift_travel_per_turn = 0.002", "lift_travel_per_turn = 1e-300"))],
 "tread 1e300": ["run", "--scenario", w("t3.toml", "[stairs]\ntread = 1e300\n")],
 "rise 1e300": ["run", "--scenario", w("t4.toml", "[stairs]\nrise = 1e300\n")],
 "width 1e300": ["run", "--scenario", w("t5.toml", "[stairs]\nwidth = 1e300\n")],
 "steps tread 5e-324": ["run", "--scenario", w("t6.toml", "[stairs]\nsteps = [{rise = 0.17, tread = 5e-324}]\n")],
 "fault at 1e300": ["run", "--scenario", w("t7.toml", "[[faults]]\nat = 1e300\nsensor = 'SFL'\nkind = 'error'\n")],
 "noise 1e300": ["run", "--scenario", w("t8.toml", "[sensors]\nnoise = 1e300\n")],
 "journal fifo": ["run", "--journal", str(fifo)],
 "record fifo": ["run", "--record", str(fifo)],
 "resume journal fifo": ["run", "--resume", "--yes", "--journal", str(fifo)],
 "resume journal /dev/zero": ["run", "--resume", "--yes", "--journal", "/dev/zero"],
 "sweep check fifo": ["sweep", "check", str(fifo)],
 "sweep check /dev/zero": ["sweep", "check", "/dev/zero"],
 "sweep check nested": ["sweep", "check", w("s.toml", nested)],
 "sweep --config /dev/zero": ["sweep", "--config", "/dev/zero", "--limit", "1", str(r.files("stairbot.inputs").joinpath("sweeps", "quick.toml"))],
 "console --scenario /dev/zero": ["console", "--scenario", "/dev/zero"],
 "console --config fifo": ["console", "--config", str(fifo)],
 "fake-boards --config /dev/zero": ["fake-boards", "--serial", "--config", "/dev/zero"],
 "fake-boards --time-scale inf": ["fake-boards", "--serial", "--time-scale", "inf"],
 "url baud=1e12": ["run", "--robot", "serial://loop://?baud=1000000000000"],
 "url watchdog=1e9": ["run", "--robot", "serial://loop://?watchdog=1000000000"],
 "url grace=inf": ["run", "--robot", "serial://loop://?grace=inf"],
 "can retries=huge": ["run", "--robot", "can://virtual/x?retries=99999999999"],
 "can a=%ff": ["run", "--robot", "can://virtual/x?a=%ff"],
 "can time_scale=nan": ["run", "--robot", "can://virtual/x?time_scale=nan"],
 "count 1e6": ["run", "--scenario", w("c.toml", "[stairs]\ncount = 1000000\n")],
 "journal resume garbage": ["run", "--resume", "--journal", w("j.jsonl", "\x00\xff garbage\n")],
}
def full_disk() -> None:  # the record may grow to 4 kB, then every write fails (EFBIG)
    resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
cases["record disk full mid-run"] = ["run", "--record", str(d / "rec.jsonl")]
cases["journal disk full mid-run"] = ["run", "--journal", str(d / "j2.jsonl")]
only = sys.argv[1:]
bad = 0
for name, argv in cases.items():
    if only and not any(o in name for o in only):
        continue
    try:
        p = subprocess.run(EXE + argv, capture_output=True, text=True, timeout=25,
                           stdin=subprocess.DEVNULL, errors="replace",
                           preexec_fn=full_disk if "disk full" in name else None)
        lines = [line for line in p.stderr.splitlines() if line.strip()]
        ok = (p.returncode in (1, 2) and len(lines) == 1 and "Traceback" not in p.stderr
              and lines[0].startswith("stairbot: error:"))
        # argparse's own form: usage lines, then one "PROG: error: argument ..." line
        ok = ok or (p.returncode == 2 and bool(lines) and lines[0].startswith("usage:")
                    and "error: argument" in lines[-1] and "Traceback" not in p.stderr)
        bad += not ok
        last = (lines[-1] if lines else p.stdout[-150:])[:230]
        print(f"{'ok ' if ok else 'BAD'} {name:24} rc={p.returncode} lines={len(lines)} {last!r}",
              flush=True)
    except subprocess.TimeoutExpired:
        bad += 1
        print(f"BAD {name:24} HANG")
print(f"{bad} BAD")
