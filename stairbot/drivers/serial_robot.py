"""The robot's two boards on one serial link.

URL format: ``serial://PORT[?option=value[&option=value...]]``

* ``PORT`` -- a device path (``serial:///dev/ttyUSB0``, a pty such as
  ``serial:///dev/pts/4``) or any pyserial URL, handed to
  ``serial.serial_for_url``: ``loop://``, ``socket://HOST:PORT``,
  ``rfc2217://HOST:PORT``, ``spy://PORT`` ...
  (``serial://socket://127.0.0.1:5000?baud=1000000``).
* options (the query after the last ``?``; keys not listed here go back to
  the pyserial URL, e.g. ``logging=debug`` for ``socket://``):

  - ``baud=N``        bit rate, default 1000000 (UART 8N1); 50 to 20000000
  - ``timeout=S``     seconds to wait for a reply, default 0.05; 0 < S <= 60;
                      (retries + 1) x timeout must be below watchdog - one
                      tick (``timing.py``), else refused
  - ``retries=N``     re-sends of a query that timed out, default 2; 0 to 100
  - ``lost=N``        unanswered commands in a row that mean the link is
                      lost (once the grace period is over), default 3; 1 to
                      1000
  - ``grace=S``       seconds a board may stay silent before the link is
                      lost, default 0.5: until then a query that got no reply
                      after its retries is sent again (line noise is ridden
                      out); 0 = lost at the first query given up; at most 60
  - ``watchdog=MS``   the boards' watchdog in ms of the robot's clock, set
                      at open, default 250 (0 = off); at most 65535
  - ``lockstep=1``    simulation only: the fake boards' world advances only
                      when the host's clock sends StepTo, once per tick
                      (``stairbot.fakes.lockstep`` opens such boards)
  - ``time_scale=X``  simulation only: the fake boards run X times real time;
                      the host's clock runs at the same rate, and timeout,
                      grace and watchdog are times of that clock (the host
                      waits timeout / X of wall time); 0.01 to 1000
  - ``log=FILE``      write every frame sent and received to FILE, one line
                      each: time, TX or RX, the bytes on the line in hex
                      (``frame_log.py``); flushed as written

Every number must be finite and within its bounds (``url_options.py``); the
query must decode as UTF-8.

A device port is held by one host at a time (``port_lock.py``): a second
``stairbot run`` or console on it is refused with one line naming the
process that holds it (PortBusyError, exit 1).

The board logic -- Robot protocol, handshake, keepalive, link health, lost
links -- is ``board_robot.BoardRobot``; this module adds the serial port and
the ``SerialLink`` (``serial_link.py``) that frames messages for it.
"""

from __future__ import annotations

import io
import os
from urllib.parse import urlencode

import serial

from stairbot.drivers.board_session import open_board_session, wanted_side_pair
from stairbot.drivers.frame_log import SerialFrameLog
from stairbot.drivers.port_lock import PortLock, serial_lock_key, take_port_lock
from stairbot.drivers.serial_link import FdChannel, PortChannel, SerialLink
from stairbot.drivers.timing import check_ride_through, link_timing
from stairbot.drivers.url_options import number_option, query_pairs
from stairbot.errors import RobotUrlError
from stairbot.inputs.config import RobotConfig
from stairbot.run.robots import RobotOptions, RobotSession

DEFAULTS: dict[str, float] = {
    "baud": 1_000_000, "timeout": 0.05, "retries": 2, "lost": 3, "watchdog": 250,
    "lockstep": 0, "time_scale": 1.0, "grace": 0.5,
}


def parse_serial_url(url: str) -> tuple[str, dict[str, float]]:
    """(pyserial port, options) of a ``serial://`` URL.  RobotUrlError names
    the option and what is allowed."""
    port, opts, _ = parse_serial_url_log(url)
    return port, opts


def parse_serial_url_log(url: str) -> tuple[str, dict[str, float], str | None]:
    """(pyserial port, options, frame log path or None) of a ``serial://`` URL."""
    if not url.startswith("serial://") or len(url) == len("serial://"):
        raise RobotUrlError(url, None, "expected serial://PORT[?baud=N&timeout=S...]")
    rest = url[len("serial://"):]
    port, _, query = rest.rpartition("?") if "?" in rest else (rest, "", "")
    opts = dict(DEFAULTS)
    passthrough: list[tuple[str, str]] = []
    log: str | None = None
    for key, value in query_pairs(url, query, strict=False):
        if key in DEFAULTS:
            opts[key] = number_option(url, key, value)
        elif key == "log":
            if not value:
                raise RobotUrlError(url, "log", "no file name; e.g. log=run.txt")
            log = value
        else:
            passthrough.append((key, value))
    if passthrough:
        port += ("&" if "?" in port else "?") + urlencode(passthrough)
    if not port:
        raise RobotUrlError(url, None, "no port; e.g. serial:///dev/ttyUSB0")
    return port, opts, log


class _LockedPort:
    """A pyserial port and the lock taken for it, closed together."""

    def __init__(self, port: serial.SerialBase, lock: PortLock | None) -> None:
        self.port = port
        self.lock = lock

    def close(self) -> None:
        try:
            self.port.close()
        finally:
            if self.lock is not None:
                self.lock.release()


def _own_terminal(path: str) -> bool:
    """Whether ``path`` is the terminal this process runs in: ``/dev/tty``,
    or the device of its standard input, output or error."""
    if path == "/dev/tty":
        return True
    for fd in (0, 1, 2):
        try:
            if os.isatty(fd) and os.path.realpath(os.ttyname(fd)) == path:
                return True
        except OSError:
            continue
    return False


def open_channel(port: str, baud: int, url: str) -> FdChannel | PortChannel:
    """Open a pyserial port; a tty gets the fast fd channel.  A device path
    is locked for this host first (``port_lock.py``): PortBusyError, one
    line naming who holds it, when another stairbot has it open.
    RobotUrlError in one line when it cannot open."""
    lock: PortLock | None = None
    key = serial_lock_key(port)
    if key is not None and _own_terminal(key):
        raise RobotUrlError(url, None, f"{port} is this program's own terminal, not a "
                            "robot's port: opening it would read the operator's keys "
                            "(the emergency stop's too) and write frames to the screen")
    if key is not None:  # one host at a time, however the URL spells the port
        try:
            lock = take_port_lock(key, f"serial port {port}")
        except OSError as exc:
            raise RobotUrlError(url, None, f"cannot lock port {port}: "
                                f"{exc.strerror or exc}") from None
    exclusive = {"exclusive": True} if key is not None and key.startswith("/") else {}
    try:
        ser = serial.serial_for_url(port, baudrate=baud, timeout=0, **exclusive)
    except Exception as exc:  # noqa: BLE001 - pyserial's URL handlers raise anything
        if lock is not None:
            lock.release()
        detail = str(exc).strip() or type(exc).__name__
        raise RobotUrlError(url, None, f"cannot open port {port}: {detail}") from None
    # Only a plain POSIX port may be read around pyserial's back: a wrapper
    # such as spy:// must see every byte.
    release = lock.release if lock is not None else None
    if type(ser).__module__ != "serial.serialposix":
        return PortChannel(ser, on_close=release)
    try:
        fd = ser.fileno()
    except (AttributeError, io.UnsupportedOperation, serial.SerialException, OSError):
        return PortChannel(ser, on_close=release)
    return FdChannel(fd, owner=_LockedPort(ser, lock))


def open_serial_robot(url: str, config: RobotConfig, options: RobotOptions) -> RobotSession:
    """Open ``serial://PORT?...``.  RobotUrlError (one line) when the URL is
    malformed or the port cannot open; NoBoardError (a HardwareError, one
    line naming the board and the URL) when no board answers."""
    port, opts, log_path = parse_serial_url_log(url)
    check_ride_through(url, opts, config.algorithm.tick)
    channel = open_channel(port, int(opts["baud"]), url)
    try:
        log = SerialFrameLog(url, log_path) if log_path else None
    except RobotUrlError:
        channel.close()
        raise
    time_scale = options.time_scale or opts["time_scale"]
    timing = link_timing(opts, time_scale)
    link = SerialLink(channel, timeout_s=timing.timeout_s, retries=int(opts["retries"]),
                      max_lost=int(opts["lost"]), grace_s=timing.grace_s, log=log)
    return open_board_session(link, url, watchdog_ms=int(opts["watchdog"]),
                              lockstep=bool(opts["lockstep"]),
                              time_scale=time_scale,
                              allow_latched=options.allow_latched,
                              side_pair=wanted_side_pair(config))


__all__ = ["DEFAULTS", "open_channel", "open_serial_robot", "parse_serial_url",
           "parse_serial_url_log"]
