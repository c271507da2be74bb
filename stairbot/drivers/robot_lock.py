"""Which lock a robot URL is opened under (``port_lock.py``): the console
finds by it whether another console on this machine has the same robot open,
and where that console shares what it shows (console/sharing.py)."""

from __future__ import annotations

from pathlib import Path
from urllib.parse import urlsplit

from stairbot.drivers.can_robot import bus_lock_key, parse_can_url
from stairbot.drivers.port_lock import lock_path, serial_lock_key
from stairbot.drivers.serial_robot import parse_serial_url
from stairbot.errors import StairbotError


def robot_lock_path(url: str) -> Path | None:
    """The lock file a robot at ``url`` is opened under: its serial port's (by
    the device's real path, however the URL spells it) or its CAN bus's.
    None for a robot no lock guards (``sim://``, ``loop://``, a python-can
    ``virtual`` bus, which is the process's own) and for a URL that does not
    parse (opening it says what is wrong)."""
    scheme = urlsplit(url).scheme if "://" in url else ""
    try:
        if scheme == "serial":
            port, _ = parse_serial_url(url)
            key = serial_lock_key(port)
        elif scheme == "can":
            key, _ = bus_lock_key(parse_can_url(url))
            if "@pid" in key:
                return None
        else:
            return None
    except (StairbotError, OSError):
        return None
    return None if key is None else lock_path(key)
