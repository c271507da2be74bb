"""Running ``stairbot fake-boards`` processes, as each registers itself: the
console's connection manager lists them (console/connections.py).

Each process writes one small JSON file, ``<pid>.json``, under
``fake-boards/`` in the directory of stairbot's lock files
(:func:`~stairbot.drivers.port_lock.lock_dir`: ``$XDG_RUNTIME_DIR/stairbot``
or ``/tmp/stairbot-UID``), with the URL a host opens, its pid, its start
time and what it serves; it removes the file when it stops.  A process
killed outright (SIGKILL) cannot: a reader takes an entry whose process is
gone -- no such pid, or a pid reused by a process started at another time
(``/proc/PID/stat``'s start time) -- for stale, ignores it and removes it.
The file is the boards' own word, as their status flag is: nothing here
checks that they answer.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import stat
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from stairbot.drivers.port_lock import lock_dir

MAX_ENTRY_BYTES = 4096
"""A registry file is a few hundred bytes; a larger one is not ours."""
LATEST_START = 1e11
"""An entry's start (seconds since the epoch) after this (the year 5138), or
not a finite number, is not one stairbot wrote: the manager shows the start
as a time of day, which such a number is not."""


def registry_dir() -> Path:
    return lock_dir() / "fake-boards"


@dataclass(frozen=True)
class FakeBoards:
    """One running ``stairbot fake-boards`` process, as it registered."""

    url: str
    pid: int
    started: float
    """Its start, seconds since the epoch (wall time)."""
    wire: str
    """``serial`` or ``can``."""
    scenario: str
    config: str
    serials: str
    """The boards' serial numbers, in words (``motor board serial 1234, ...``)."""


def process_start(pid: int) -> int | None:
    """When process ``pid`` started, in clock ticks since boot (field 22 of
    ``/proc/PID/stat``); None where it cannot be read (no such process, no
    /proc)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = stat.rpartition(")")[2].split()  # after the command's name, which may hold spaces
    try:
        return int(fields[19])
    except (IndexError, ValueError):
        return None


def alive(pid: int, start: int | None) -> bool:
    """Whether the process that registered (``pid``, started at ``start``)
    still runs: the pid exists and, where /proc says when it started, it is
    the same process, not a later one given the same pid."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass  # another user's process has that pid: it exists
    except OSError:
        return False
    now = process_start(pid)
    return start is None or now is None or now == start


@contextlib.contextmanager
def registered(url: str, *, wire: str, scenario: str, config: str,
               serials: str) -> Iterator[Path | None]:
    """Register this process's boards while the block runs; the file is
    removed when it ends, however it ends (but SIGKILL).  A registry that
    cannot be written is said on stderr in one line and the boards serve
    on: a manager that does not list them is no reason to refuse them."""
    pid = os.getpid()
    entry = {"url": url, "pid": pid, "proc_start": process_start(pid), "started": time.time(),
             "wire": wire, "scenario": scenario, "config": config, "serials": serials}
    path = registry_dir() / f"{pid}.json"
    written = True
    try:
        _write_atomically(path, json.dumps(entry))
    except OSError as exc:
        print(f"stairbot fake-boards: not registered for the console's connection manager "
              f"({path}: {exc.strerror or exc})", file=sys.stderr, flush=True)
        written = False
    try:
        yield path if written else None
    finally:
        if written:
            with contextlib.suppress(OSError):
                path.unlink()


def _write_atomically(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as out:
            out.write(text)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def running() -> tuple[list[FakeBoards], list[str]]:
    """The fake boards that registered and still run, oldest first, and what
    could not be read (one line each).  Stale entries (their process gone)
    are removed, not listed."""
    found: list[FakeBoards] = []
    problems: list[str] = []
    try:
        paths = sorted(registry_dir().glob("*.json"))
    except OSError as exc:
        return [], [f"fake boards: cannot read {registry_dir()}: {exc.strerror or exc}"]
    for path in paths:
        try:
            entry = _read(path)
        except (OSError, ValueError) as exc:
            problems.append(f"fake boards: {path.name} ignored: {exc}")
            continue
        if entry is None:
            with contextlib.suppress(OSError):
                path.unlink()
            continue
        found.append(entry)
    found.sort(key=lambda e: e.started)
    return found, problems


def _read(path: Path) -> FakeBoards | None:
    """One entry; None when its process is gone.  ValueError when it is not
    an entry stairbot wrote."""
    # non-blocking: a FIFO given a registry name must not hold the reader
    # (the manager's look, and the console's quit after it) until a writer comes
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0))
    with os.fdopen(fd, "rb") as f:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise ValueError("not a regular file")
        data = f.read(MAX_ENTRY_BYTES + 1)
    if len(data) > MAX_ENTRY_BYTES:
        raise ValueError(f"larger than {MAX_ENTRY_BYTES} bytes")
    try:
        raw = json.loads(data)
        pid, start = raw["pid"], raw.get("proc_start")
        entry = FakeBoards(url=str(raw["url"]), pid=int(pid), started=float(raw["started"]),
                           wire=str(raw["wire"]), scenario=str(raw["scenario"]),
                           config=str(raw["config"]), serials=str(raw["serials"]))
    except (KeyError, TypeError, ValueError, UnicodeDecodeError) as exc:
        raise ValueError(f"not a fake-boards entry ({type(exc).__name__})") from None
    if not isinstance(pid, int) or pid <= 0 or not (start is None or isinstance(start, int)):
        raise ValueError("not a fake-boards entry (pid)")
    if not (math.isfinite(entry.started) and 0 <= entry.started <= LATEST_START):
        raise ValueError("not a fake-boards entry (started)")
    return entry if alive(entry.pid, start) else None
