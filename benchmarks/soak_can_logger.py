"""Default runs over CAN (``udp_multicast`` on loopback) with python-can's
``can.logger`` listening on the bus: does a listener change anything, and is
every frame on the wire one the DBC knows?

    python benchmarks/soak_can_logger.py [--runs 20] [--time-scale 20] [--keep DIR]

For each run: ``stairbot fake-boards --can udp_multicast/GROUP --time-scale X``
(real time, scaled: not lockstep), ``python -m can.logger -i udp_loopback -c
GROUP -f run-N.log`` (stairbot registers its loopback bus with python-can as
the interface ``udp_loopback``), then ``stairbot run --robot URL --json``.
Prints one line a run -- outcome, steps, fell, wall time, the holds (the
robot stood, every motor stopped, for a stale sensor or IMU reading: a late
reply), what the link counted, frames the logger wrote and how many of them the shipped DBC
(stairbot/drivers/stairbot.dbc, via cantools with the frame id mask
0x1FFC0000: a frame's id carries the host's session and seq below its base)
cannot decode -- and the count
of completed runs.  Exit status 1 unless every run completed and every frame
decoded.

Scaled real time needs the machine's attention: on a loaded machine the
boards' world falls behind and the robot stops itself, correctly ("IMU
stale").  Run it on a quiet machine.
"""

from __future__ import annotations

import argparse
import json
import signal
import subprocess
import sys
import tempfile
import time
from importlib import resources
from pathlib import Path

import can
import cantools

from stairbot.drivers.can_wire import FRAME_ID_MASK


def decode_count(log: Path) -> tuple[int, int]:
    """(frames in the candump log, frames the DBC cannot decode)."""
    db = cantools.database.load_string(
        resources.files("stairbot.drivers").joinpath("stairbot.dbc").read_text("utf-8"),
        database_format="dbc", strict=True, frame_id_mask=FRAME_ID_MASK)
    assert isinstance(db, cantools.database.can.Database)
    frames = unknown = 0
    for msg in can.LogReader(str(log)):
        if msg.is_error_frame:
            continue
        frames += 1
        try:
            # get_message_by_frame_id applies the mask; decode_message does not
            db.get_message_by_frame_id(msg.arbitration_id).decode(bytes(msg.data))
        except (KeyError, ValueError, cantools.database.DecodeError):
            unknown += 1
    return frames, unknown


def one_run(n: int, scale: float, folder: Path) -> tuple[bool, str]:
    group = f"239.74.165.{n % 250 + 1}"
    log = folder / f"run-{n}.log"
    boards = subprocess.Popen(
        [sys.executable, "-m", "stairbot", "fake-boards", "--can", f"udp_multicast/{group}",
         "--time-scale", str(scale)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    logger = subprocess.Popen(
        [sys.executable, "-m", "can.logger", "-i", "udp_loopback", "-c", group, "-f", str(log)],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    t0 = time.monotonic()
    try:
        assert boards.stdout is not None and logger.stdout is not None
        # timeout, grace and watchdog are robot time (docs/protocol.md, "Riding
        # through noise in real time"): keep the wall-time margins this soak
        # soaks the logger and the host's stalls with (50 ms, 0.5 s, 250 ms),
        # X times longer in robot time, rather than shrink them X times.
        url = boards.stdout.readline().strip() + (
            f"&timeout={0.05 * scale:g}&grace={0.5 * scale:g}"
            f"&watchdog={min(65535, round(250 * scale))}")
        logger.stdout.readline()  # "Connected to ...": listening
        with tempfile.TemporaryDirectory() as tmp:  # a journal of its own (soak_faults.py)
            host = subprocess.run([sys.executable, "-m", "stairbot", "run", "--robot", url,
                                   "--journal", str(Path(tmp) / "journal.jsonl"), "--json",
                                   "-q"], capture_output=True, text=True, timeout=1800)
    finally:
        logger.send_signal(signal.SIGINT)  # can.logger flushes and closes its file
        boards.terminate()
        for proc in (logger, boards):
            try:
                proc.communicate(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.communicate()
    wall = time.monotonic() - t0
    frames, unknown = decode_count(log) if log.exists() else (0, 0)
    try:
        r = json.loads(host.stdout)
    except json.JSONDecodeError:
        last = (host.stderr.strip().splitlines() or ["no output"])[-1]
        return False, f"run {n:2}: exit {host.returncode}: {last}"
    link = r.get("link") or {}
    keys = ("retries", "revived", "lost", "late", "stray", "duplicates")
    counts = " ".join(f"{k} {link[k]}" for k in keys if k in link)
    ok = r["outcome"] == "completed" and not r["fell"] and frames > 0 and unknown == 0
    return ok, (f"run {n:2}: {r['outcome']:9} up {r['steps_climbed']} down "
                f"{r['steps_descended']} fell {r['fell']!s:5} {wall:5.1f} s  "
                f"holds {r.get('pauses', 0)}  {counts}  "
                f"logged {frames} frames, {unknown} unknown to the DBC"
                + (f"  error: {r['error']}" if r.get("error") else ""))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--time-scale", type=float, default=20.0)
    ap.add_argument("--keep", type=Path, help="keep the candump logs here")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        good = 0
        for n in range(1, args.runs + 1):
            ok, line = one_run(n, args.time_scale, folder)
            good += ok
            print(line, flush=True)
    print(f"\n{good}/{args.runs} completed (default runs, udp_multicast on loopback, "
          f"--time-scale {args.time_scale:g}, can.logger on the bus, every frame decoded)")
    return 0 if good == args.runs else 1


if __name__ == "__main__":
    sys.exit(main())
