"""One host on a serial port or a CAN bus at a time, on this machine.

Two hosts on one port would each take the other's replies and interleave
their commands: the robot would obey neither faithfully.  So opening a
``serial://`` port -- whatever its URL spelling: a device path, a symlink to
it, ``spy://`` or ``alt://`` around it, ``hwgrep://`` finding it, or one
``socket://``/``rfc2217://`` endpoint -- or a ``can://`` bus takes an
advisory lock (``fcntl.flock``) on a lock file of its own per port or bus,
under ``$XDG_RUNTIME_DIR/stairbot`` (or ``/tmp/stairbot-UID``), held until
it is closed.  The kernel drops it
when the process dies, however it dies, so a crash leaves no stale lock.
The file says who holds it (the process id and its command line), and a
second ``stairbot run`` or console on the same port is refused with one
line naming that holder (:class:`~stairbot.errors.PortBusyError`).  The
boards' own lease (docs/protocol.md, "One host owns the boards") guards the
robot against hosts on other machines, which no lock here can see.

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
from urllib.parse import urlsplit

from serial.tools import list_ports

from stairbot.errors import PortBusyError

HOLDER_MAX = 200  # characters of the holder's command line kept in the lock file


def lock_dir() -> Path:
    runtime = os.environ.get("XDG_RUNTIME_DIR")
    return Path(runtime) / "stairbot" if runtime else Path(f"/tmp/stairbot-{os.getuid()}")


def lock_path(key: str) -> Path:
    """The lock file of ``key`` (a device's real path, or a bus or endpoint name)."""
    slug = re.sub(r"[^A-Za-z0-9]+", "_", key).strip("_") or "port"
    return lock_dir() / f"{slug}.lock"


WRAPPERS = ("spy", "alt")  # pyserial URL handlers that open the port they wrap
ENDPOINTS = ("socket", "rfc2217")  # handlers that open a network endpoint


def serial_lock_key(port: str) -> str | None:
    """What ``port`` (a device path or a pyserial URL) opens, as the key of
    its lock: a device by its real path (two names of one device, such as a
    symlink in /dev/serial/by-id/, share one lock), a wrapper by what it
    wraps, a network endpoint by host and port.  None for ``loop://``, which
    is this process's own."""
    if "://" not in port:
        return os.path.realpath(port)
    scheme, rest = port.split("://", 1)
    scheme = scheme.lower()
    if scheme in WRAPPERS:
        return serial_lock_key(rest.split("?", 1)[0])
    if scheme == "hwgrep":
        pattern = rest.split("&", 1)[0]
        found = sorted(list_ports.grep(pattern))
        return os.path.realpath(found[0].device) if found else None
    if scheme in ENDPOINTS:
        where = urlsplit(f"{scheme}://{rest}")
        return f"{scheme}:{(where.hostname or '').lower()}:{where.port}"
    return None


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


def take_port_lock(key: str, what: str) -> PortLock:
    """Lock ``key`` (``serial_lock_key``, or a CAN bus's name) for this
    process.  PortBusyError (one line naming ``what`` -- "serial port
    /dev/ttyUSB0", "CAN bus virtual/bus0" -- and who holds it) when another
    stairbot has it open; OSError when the lock file cannot be made."""
    path = lock_path(key)
    path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = os.pread(fd, 4 * HOLDER_MAX, 0).decode("utf-8", "replace").strip()
        os.close(fd)
        who = f" ({holder})" if holder else ""
        raise PortBusyError(f"{what} is in use by another stairbot{who}: close that one "
                            "first (one host owns the robot)") from None
    except BaseException:
        os.close(fd)
        raise
    os.ftruncate(fd, 0)
    os.pwrite(fd, _holder().encode("utf-8", "replace") + b"\n", 0)
    return PortLock(fd, path)
