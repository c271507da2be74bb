"""The robot's two boards on one serial link.

URL format: ``serial://PORT[?option=value[&option=value...]]``

* ``PORT`` -- a device path (``serial:///dev/ttyUSB0``, a pty such as
  ``serial:///dev/pts/4``) or any pyserial URL, handed to
  ``serial.serial_for_url``: ``loop://``, ``socket://HOST:PORT``,
  ``rfc2217://HOST:PORT``, ``spy://PORT`` ...
  (``serial://socket://127.0.0.1:5000?baud=1000000``).
* options (the query after the last ``?``; keys not listed here go back to
  the pyserial URL, e.g. ``logging=debug`` for ``socket://``):

  - ``baud=N``        bit rate, default 1000000 (UART 8N1)
  - ``timeout=S``     seconds to wait for a reply, default 0.05
  - ``retries=N``     re-sends of a query that timed out, default 2
  - ``lost=N``        unanswered commands in a row that mean the link is
                      lost (once the grace period is over), default 3
  - ``grace=S``       seconds a board may stay silent before the link is
                      lost, default 0.5: until then a query that got no reply
                      after its retries is sent again (line noise is ridden
                      out); 0 = lost at the first query given up
  - ``watchdog=MS``   the boards' watchdog in wall-clock ms, set at open,
                      default 250 (0 = off)
  - ``lockstep=1``    simulation only: the fake boards' world advances only
                      when the host's clock sends StepTo, once per tick
                      (``stairbot.fakes.lockstep`` opens such boards)
  - ``time_scale=X``  simulation only: the fake boards run X times real time;
                      the host's wall clock runs at the same rate

The board logic -- Robot protocol, handshake, keepalive, link health, lost
links -- is ``board_robot.BoardRobot``; this module adds the serial port and
the ``SerialLink`` (``serial_link.py``) that frames messages for it.
"""

from __future__ import annotations

import io
from urllib.parse import parse_qsl, urlencode

import serial

from stairbot.config import RobotConfig
from stairbot.drivers.board_robot import open_board_session
from stairbot.drivers.serial_link import FdChannel, PortChannel, SerialLink
from stairbot.errors import RobotUrlError
from stairbot.robots import RobotOptions, RobotSession

DEFAULTS: dict[str, float] = {
    "baud": 1_000_000, "timeout": 0.05, "retries": 2, "lost": 3, "watchdog": 250,
    "lockstep": 0, "time_scale": 1.0, "grace": 0.5,
}
_INTS = {"baud", "retries", "lost", "watchdog", "lockstep"}


def parse_serial_url(url: str) -> tuple[str, dict[str, float]]:
    """(pyserial port, options) of a ``serial://`` URL.  RobotUrlError names
    the option and what is allowed."""
    if not url.startswith("serial://") or len(url) == len("serial://"):
        raise RobotUrlError(url, None, "expected serial://PORT[?baud=N&timeout=S...]")
    rest = url[len("serial://"):]
    port, _, query = rest.rpartition("?") if "?" in rest else (rest, "", "")
    opts = dict(DEFAULTS)
    passthrough: list[tuple[str, str]] = []
    for key, value in parse_qsl(query, keep_blank_values=True):
        if key not in DEFAULTS:
            passthrough.append((key, value))
            continue
        try:
            number = int(value) if key in _INTS else float(value)
        except ValueError:
            kind = "an integer" if key in _INTS else "a number"
            raise RobotUrlError(url, key, f"{value!r} is not {kind}") from None
        if number < 0 or (key in {"baud", "timeout", "time_scale"} and number == 0):
            raise RobotUrlError(url, key, f"{value} is out of range; allowed: > 0"
                                if key in {"baud", "timeout", "time_scale"} else ">= 0")
        if key == "lockstep" and number not in (0, 1):
            raise RobotUrlError(url, key, f"{value} is not allowed; allowed: 0 or 1")
        opts[key] = number
    if passthrough:
        port += ("&" if "?" in port else "?") + urlencode(passthrough)
    if not port:
        raise RobotUrlError(url, None, "no port; e.g. serial:///dev/ttyUSB0")
    return port, opts


def open_channel(port: str, baud: int, url: str) -> FdChannel | PortChannel:
    """Open a pyserial port; a tty gets the fast fd channel.  RobotUrlError
    in one line when it cannot open."""
    try:
        ser = serial.serial_for_url(port, baudrate=baud, timeout=0)
    except (serial.SerialException, ValueError, OSError) as exc:
        raise RobotUrlError(url, None, f"cannot open port {port}: {exc}") from None
    # Only a plain POSIX port may be read around pyserial's back: a wrapper
    # such as spy:// must see every byte.
    if type(ser).__module__ != "serial.serialposix":
        return PortChannel(ser)
    try:
        fd = ser.fileno()
    except (AttributeError, io.UnsupportedOperation, serial.SerialException, OSError):
        return PortChannel(ser)
    return FdChannel(fd, owner=ser)


def open_serial_robot(url: str, config: RobotConfig, options: RobotOptions) -> RobotSession:
    """Open ``serial://PORT?...``.  RobotUrlError (one line) when the URL is
    malformed or the port cannot open; NoBoardError (a HardwareError, one
    line naming the board and the URL) when no board answers."""
    port, opts = parse_serial_url(url)
    channel = open_channel(port, int(opts["baud"]), url)
    link = SerialLink(channel, timeout_s=opts["timeout"], retries=int(opts["retries"]),
                      max_lost=int(opts["lost"]), grace_s=opts["grace"])
    return open_board_session(link, url, watchdog_ms=int(opts["watchdog"]),
                              lockstep=bool(opts["lockstep"]),
                              time_scale=options.time_scale or opts["time_scale"],
                              allow_latched=options.allow_latched)


__all__ = ["DEFAULTS", "open_channel", "open_serial_robot", "parse_serial_url"]
