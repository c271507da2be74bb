"""One host on a serial port at a time.

Two hosts on one port would each take the other's replies and interleave
their commands: the robot would obey neither faithfully.  So opening a
``serial://`` device takes an advisory lock (``fcntl.flock``) on a lock file
of its own per port, under ``$XDG_RUNTIME_DIR/stairbot`` (or
``/tmp/stairbot-UID``), held until the port is closed.  The kernel drops it
when the process dies, however it dies, so a crash leaves no stale lock.
The file says who holds it (the process id and its command line), and a
second ``stairbot run`` or console on the same port is refused with one
line naming that holder (:class:`~stairbot.errors.PortBusyError`).

The tty itself is opened ``exclusive`` as well (pyserial flocks its
descriptor): that also keeps out another user's stairbot, whose lock files
live elsewhere, and any other program that locks the port the same way.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import re
import sys
from pathlib import Path

from stairbot.errors import PortBusyError

HOLDER_MAX = 200  # characters of the holder's command line kept in the lock file


def lock_dir() -> Path:
    runtime = os.environ.get("XDG_RUNTIME_DIR")
    return Path(runtime) / "stairbot" if runtime else Path(f"/tmp/stairbot-{os.getuid()}")


def lock_path(port: str) -> Path:
    """The lock file of ``port`` (a device path), by its real path: two names
    of one device (a symlink such as /dev/serial/by-id/...) share one lock."""
    real = os.path.realpath(port)
    slug = re.sub(r"[^A-Za-z0-9]+", "_", real).strip("_") or "port"
    return lock_dir() / f"{slug}.lock"


class PortLock:
    """The lock on one port, held until :meth:`release` (or the process ends)."""

    def __init__(self, fd: int, path: Path) -> None:
        self._fd = fd
        self.path = path

    def release(self) -> None:
        if self._fd < 0:
            return
        fd, self._fd = self._fd, -1
        with contextlib.suppress(OSError):
            fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)


def _holder() -> str:
    argv = [Path(sys.argv[0]).name, *sys.argv[1:]] if sys.argv and sys.argv[0] else []
    return f"pid {os.getpid()}: {' '.join(argv)}"[:HOLDER_MAX]


def take_port_lock(port: str) -> PortLock:
    """Lock ``port`` for this process.  PortBusyError (one line naming the
    port and who holds it) when another stairbot has it open; OSError when
    the lock file cannot be made."""
    path = lock_path(port)
    path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = os.pread(fd, 4 * HOLDER_MAX, 0).decode("utf-8", "replace").strip()
        os.close(fd)
        who = f" ({holder})" if holder else ""
        raise PortBusyError(f"serial port {port} is in use by another stairbot{who}: "
                            "close that one first (one host on a port at a time)") from None
    except BaseException:
        os.close(fd)
        raise
    os.ftruncate(fd, 0)
    os.pwrite(fd, _holder().encode("utf-8", "replace") + b"\n", 0)
    return PortLock(fd, path)
