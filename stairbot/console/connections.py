"""What the connection manager (console/connect_screen.py) lists: the robots
this machine offers, grouped, each a URL the console opens and one line
saying what it is.

* **Fake boards**: running ``stairbot fake-boards`` processes, as they
  registered (:mod:`stairbot.fakes.registry`).
* **Serial ports**: pyserial's ``list_ports.comports()``, as ``serial://DEVICE``.
* **CAN buses**: python-can's ``detect_available_configs``, asked one
  interface at a time, so one interface that raises (a vendor library
  missing, a driver's error) costs only its own entries and a line; what
  python-can logs meanwhile is kept off the screen.  Listed only where
  stairbot opens the bus for boards in another process (see :data:`SKIPPED`).
* **Simulation**: ``sim://``, on the console's robot and scenario.
* **Recent**: the URLs this console opened before (console/recent.py).

Every source is asked in :func:`gather` (blocking: the screen calls it on a
worker thread); none of them can make it raise.
"""

from __future__ import annotations

import ipaddress
import logging
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import quote

import can
from serial.tools import list_ports

from stairbot.console import recent
from stairbot.drivers.can_robot import parse_can_url
from stairbot.errors import RobotUrlError
from stairbot.fakes import registry

GROUPS = ("Fake boards", "Serial ports", "CAN buses", "Simulation", "Recent")

SKIPPED: dict[str, str] = {
    "virtual": "a bus inside one process: no boards of another process are on it",
    "serial": "offers every serial port (listed above), not a CAN adapter it found",
    "socketcand": "finding one waits seconds for network beacons; type "
                  "can://socketcand/CHANNEL?host=H&port=P",
}
"""python-can interfaces not asked, and why (said under CAN buses)."""


@dataclass(frozen=True)
class Entry:
    """One row: the URL it opens, and what it is in one line."""

    group: str
    url: str
    description: str
    robot: str | None = None
    """Fake boards: the robot they simulate, as they registered (a shipped
    name or a config file)."""


@dataclass
class Listing:
    """Everything found, and a line for each source that failed or was left out."""

    entries: list[Entry] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    """CAN configurations found but not listed, each with why."""

    def group(self, name: str) -> list[Entry]:
        return [e for e in self.entries if e.group == name]


def gather(*, sim: str, comports: Callable[[], Any] | None = None,
           detect: Callable[..., Any] | None = None) -> Listing:
    """Ask every source (``sim``: the simulation's line).  ``comports`` and
    ``detect`` are pyserial's and python-can's, looked up at the call (a
    test replaces them on their modules)."""
    out = Listing()
    _fake_boards(out)
    _serial_ports(out, comports or list_ports.comports)
    _can_buses(out, detect or can.detect_available_configs)
    out.entries.append(Entry("Simulation", "sim://", sim))
    urls, problem = recent.load()
    out.entries.extend(Entry("Recent", u, "opened before") for u in urls)
    if problem:
        out.problems.append(problem)
    return out


def _fake_boards(out: Listing) -> None:
    try:
        found, problems = registry.running()
    except Exception as exc:  # noqa: BLE001 - a source's failure is a line, not a traceback
        out.problems.append(f"fake boards: cannot list them: {_why(exc)}")
        return
    out.problems.extend(problems)
    for b in found:
        since = time.strftime("%H:%M:%S", time.localtime(b.started))
        out.entries.append(Entry("Fake boards", b.url,
                                 f"pid {b.pid} since {since}, {b.config} robot, "
                                 f"{b.scenario} stairs ({b.serials})", robot=b.config))


def _serial_ports(out: Listing, comports: Callable[[], Any]) -> None:
    try:
        ports = sorted(comports(), key=lambda p: str(p.device))
    except Exception as exc:  # noqa: BLE001
        out.problems.append(f"serial ports: cannot list them: {_why(exc)}")
        return
    for port in ports:
        words = [str(port.description)] if port.description and port.description != "n/a" \
            else ["no description from the system"]
        if getattr(port, "serial_number", None):
            words.append(f"serial number {port.serial_number}")
        if getattr(port, "manufacturer", None):
            words.append(str(port.manufacturer))
        out.entries.append(Entry("Serial ports", f"serial://{port.device}", ", ".join(words)))


def _can_buses(out: Listing, detect: Callable[..., Any]) -> None:
    failed: dict[str, list[str]] = {}
    seen: set[str] = set()
    for name in sorted(can.VALID_INTERFACES):
        if name in SKIPPED:
            out.skipped.append(f"{name}: {SKIPPED[name]}")
            continue
        try:
            with _quiet_can_log(name):
                configs = list(detect(interfaces=[name]))
        except Exception as exc:  # noqa: BLE001 - one interface's failure is its own
            failed.setdefault(_why(exc), []).append(name)
            continue
        for cfg in configs:
            entry, why = _can_entry(cfg)
            if entry is not None and entry.url not in seen:
                seen.add(entry.url)
                out.entries.append(entry)
            elif why and why not in out.skipped:
                out.skipped.append(why)
    for why, names in failed.items():
        out.problems.append(f"CAN: {', '.join(names)}: cannot look for buses: {why}")


def _can_entry(cfg: Any) -> tuple[Entry | None, str | None]:
    """The row of one configuration python-can found, or why it is not one."""
    try:
        interface, channel = str(cfg["interface"]), cfg.get("channel")
    except (KeyError, TypeError, AttributeError):
        return None, None
    if interface in SKIPPED:
        return None, None  # offered under another interface's name (udp_loopback)
    if channel is None:
        return None, f"{interface}: found without a channel"
    channel = str(channel)
    if interface == "udp_multicast":
        try:
            group = ipaddress.ip_address(channel)
        except ValueError:
            return None, f"udp_multicast {channel}: not a group address"
        if group.version == 6:
            return None, (f"udp_multicast {channel}: an IPv6 group, and stairbot keeps "
                          "udp_multicast on loopback, IPv4 only (type ?lan=1: the network)")
        entry = Entry("CAN buses", f"can://udp_multicast/{channel}",
                      "python-can udp_multicast, on this machine's loopback only")
    else:
        entry = Entry("CAN buses", f"can://{interface}/{quote(channel, safe='/:.')}",
                      f"python-can {interface} channel {channel}")
    try:
        parse_can_url(entry.url)  # the driver's own reading of it
    except RobotUrlError as exc:
        return None, f"{interface} {channel}: {exc}"
    return entry, None


def _why(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__


class _Asking(logging.Filter):
    """Drops the records of one interface being asked: those logged by the
    thread asking, and those of its own loggers (``can.systec``) from any
    thread (an interface may look on a thread of its own)."""

    def __init__(self, interface: str) -> None:
        super().__init__()
        self.thread = threading.get_ident()
        self.names = (f"can.{interface}", f"can.interfaces.{interface}")

    def filter(self, record: logging.LogRecord) -> bool:
        return record.thread != self.thread and not record.name.startswith(self.names)


@contextmanager
def _quiet_can_log(interface: str) -> Iterator[None]:
    """python-can's interfaces log what they lack ("Kvaser canlib is
    unavailable") when asked to look: off the operator's screen (a bus in
    use on another thread logs as before).  A filter on each handler, since
    a logger's own filters do not see its children's records."""
    quiet = _Asking(interface)
    handlers = [*logging.getLogger().handlers, *logging.getLogger("can").handlers]
    last = logging.lastResort
    for h in [*handlers, *([last] if last is not None else [])]:
        h.addFilter(quiet)
    try:
        yield
    finally:
        for h in [*handlers, *([last] if last is not None else [])]:
            h.removeFilter(quiet)
