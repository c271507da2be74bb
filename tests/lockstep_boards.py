"""Fake boards in lockstep in a process of their own, on a pseudo-terminal
(`stairbot fake-boards --serial --lockstep`): their world stands still while
no host steps it, so a test on them is as fast as the machine and cannot
flake on timing.  One helper for every test that needs them (a module of
its own, not conftest.py)."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path


def stairbot(*args: str, env: dict[str, str] | None = None,
             cwd: Path | None = None) -> subprocess.Popen[str]:
    """``python -m stairbot ARGS``, its output piped, its input closed."""
    return subprocess.Popen([sys.executable, "-m", "stairbot", *args], text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            stdin=subprocess.DEVNULL, env=env or dict(os.environ), cwd=cwd)


@dataclass
class Boards:
    """Served boards: their URL and process; once stopped, what they said on
    stderr and their exit status (None if they had to be killed)."""

    url: str
    proc: subprocess.Popen[str]
    stderr: str = ""
    returncode: int | None = None
    motor_serial: int = 0
    """The motor board's serial number, as their banner says (drawn each launch)."""

    @property
    def identity(self) -> dict[str, dict[str, int]]:
        """What a journal is kept by (:func:`~stairbot.run.journaled.default_path`)."""
        return {"motor": {"serial": self.motor_serial}}


@contextmanager
def lockstep_boards(cwd: Path, env: dict[str, str] | None = None,
                    stop: signal.Signals = signal.SIGINT, *,
                    scenario: str | None = None,
                    config: str | None = None, can: str | None = None,
                    firmware: str | None = None) -> Iterator[Boards]:
    """Serve fake boards in lockstep (on ``scenario``, default the default
    stairs; for ``config``, default the reference robot) on a pty, or on the
    CAN bus ``can`` names (``udp_multicast/GROUP?port=N``), until the block
    ends, then stop them with ``stop`` (unless the block did), killing them
    after 10 s.  ``firmware``: serve the boards' C firmware of that kind
    (``--firmware native``) instead of the Python fakes.  ``cwd`` elsewhere
    than the source tree: the installed package runs."""
    more = (*(() if scenario is None else ("--scenario", scenario)),
            *(() if config is None else ("--config", config)))
    wire = ("--serial",) if can is None else ("--can", can)
    if firmware is not None:
        wire += ("--firmware", firmware)
    proc = stairbot("fake-boards", *wire, "--lockstep", *more, env=env, cwd=cwd)
    assert proc.stdout is not None
    boards = Boards(proc.stdout.readline().strip(), proc)
    banner = ""
    try:
        assert boards.url.startswith("serial:///dev/" if can is None else "can://") \
            and boards.url.endswith("lockstep=1"), boards.url
        assert proc.stderr is not None
        while "serving on" not in banner:  # after a config note, if any
            line = proc.stderr.readline()
            assert line, banner
            banner += line
        found = re.search(r"motor board serial (\d+)", banner)
        assert found is not None, banner
        boards.motor_serial = int(found.group(1))
        yield boards
    finally:
        if proc.poll() is None:
            proc.send_signal(stop)
        try:
            _, rest = proc.communicate(timeout=10)
            boards.stderr = banner + rest
            boards.returncode = proc.returncode
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()


@contextmanager
def fake_boards(cwd: Path) -> Iterator[str]:
    """:func:`lockstep_boards`, yielding their URL alone."""
    with lockstep_boards(cwd) as boards:
        yield boards.url


def last_tick(journal: Path) -> dict[str, object]:
    """The journal's last whole line (a run still writing may have begun the next)."""
    whole = journal.read_text().rpartition("\n")[0]
    return json.loads(whole.rpartition("\n")[2]) if whole else {}


def kill_mid_lift(url: str, journal: Path, env: dict[str, str], cwd: Path,
                  *args: str, phase: str = "ascent_lift_first",
                  lift: tuple[str, int] = ("MTF", 1)) -> dict[str, object]:
    """``stairbot run --robot URL ARGS`` killed (-9) while a lift moves in
    ``phase`` (default: segment 1 lifting, ascent 3; ``lift`` names the motor
    and the sign of its speed), watched through ``journal`` (where ARGS, or
    the default, put it); the journal's last tick then."""
    host = stairbot("run", "--robot", url, *args, "-q", env=env, cwd=cwd)
    deadline = time.monotonic() + 120
    motor, sign = lift
    try:
        while time.monotonic() < deadline:
            if journal.exists():
                tick = last_tick(journal)
                command = tick.get("command")
                if (tick.get("phase") == phase and isinstance(command, dict)
                        and sign * command.get(motor, 0) > 0):
                    break
            time.sleep(0.02)
        else:
            raise AssertionError(f"the run never reached {phase} moving {motor}")
    finally:
        host.kill()  # SIGKILL: no finally, no close, no end record
        host.wait()
    return last_tick(journal)
