"""Open a robot by URL, the way pyserial's ``serial_for_url`` picks a transport.

URL schemes (each handler documents its own grammar in its module header):

* ``sim://``                      the in-process pymunk simulation (stairbot.fakes.sim)
* ``serial://PORT?baud=...``      boards on a serial link; PORT is any pyserial URL
* ``can://INTERFACE/CHANNEL?...`` boards on a CAN bus, any python-can interface

Third parties add schemes with an entry point in the ``stairbot.robots`` group,
whose value is a factory ``f(url, config, options) -> RobotSession``.  A driver
takes a URL and a config; only a simulated robot reads ``options.world`` (the
stairs and start pose it simulates).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from importlib import import_module
from importlib.metadata import entry_points
from urllib.parse import parse_qs, urlsplit

from stairbot.errors import RobotUrlError
from stairbot.hardware import Clock, HasScene, Robot
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario

TIME_SCALE_MIN, TIME_SCALE_MAX = 0.01, 1000.0
"""The pace a simulated robot may run at, simulated seconds per wall second
(``--time-scale``, a URL's ``time_scale=``): slower than 1/100 a run of
minutes takes days; faster than 1000x the fake boards' timers fall below a
millisecond."""


@dataclass(frozen=True)
class RobotOptions:
    """How to run: ``realtime`` paces a simulation to the wall clock;
    ``time_scale`` (sim seconds per wall second) paces it faster or slower;
    ``world`` is the scenario a simulated robot (``sim://``) is placed in —
    drivers for real boards never read it.  ``allow_latched`` opens boards
    that hold a latch (e-stop, tripped watchdog) instead of refusing them:
    ``stairbot clear`` only."""

    realtime: bool = False
    time_scale: float | None = None
    world: Scenario | None = None
    allow_latched: bool = False


@dataclass
class RobotSession:
    """An opened robot with the clock that goes with it.  ``sim`` is the
    in-process simulation the console can draw (sim://); None for a robot on
    a wire, fake boards included (their world runs in another process)."""

    robot: Robot
    clock: Clock
    url: str
    simulated: bool
    sim: HasScene | None = None

    def close(self) -> None:
        self.robot.close()


RobotFactory = Callable[[str, RobotConfig, RobotOptions], RobotSession]

# Built-in schemes, imported lazily so the core never imports pymunk/serial/can.
_BUILTIN: dict[str, str] = {
    "sim": "stairbot.fakes.sim:open_sim_robot",
    "serial": "stairbot.drivers.serial_robot:open_serial_robot",
    "can": "stairbot.drivers.can_robot:open_can_robot",
}

ENTRY_POINT_GROUP = "stairbot.robots"

LOCKSTEP_MODULE = "stairbot.fakes.lockstep"
"""Fake boards in lockstep (a ``lockstep`` option in a board URL) are a
simulation: this module of the fakes registers the robot that opens them with
the drivers, and is loaded before such a URL is handed to its driver."""


def known_schemes() -> dict[str, str]:
    """Scheme -> "module:attribute" for every robot URL scheme available."""
    found = dict(_BUILTIN)
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        found.setdefault(ep.name, ep.value)
    return found


def _load(target: str, url: str) -> RobotFactory:
    module_name, _, attr = target.partition(":")
    try:
        module = import_module(module_name)
        factory: RobotFactory = getattr(module, attr)
    except (ImportError, AttributeError) as exc:
        raise RobotUrlError(url, None, f"the handler {target} cannot be loaded: {exc}") from exc
    return factory


def open_robot(
    url: str,
    config: RobotConfig,
    options: RobotOptions | None = None,
) -> RobotSession:
    """Open the robot named by ``url``.  Raises RobotUrlError for an unknown
    scheme or a malformed URL, HardwareError for a robot that cannot be
    reached (the handler says why)."""
    scheme = urlsplit(url).scheme if "://" in url else ""
    schemes = known_schemes()
    if scheme not in schemes:
        allowed = ", ".join(f"{s}://" for s in sorted(schemes))
        what = f"unknown scheme {scheme!r}" if scheme else "not a robot URL"
        raise RobotUrlError(url, None, f"{what}; allowed: {allowed}")
    factory = _load(schemes[scheme], url)
    if "lockstep" in parse_qs(urlsplit(url).query):
        try:
            import_module(LOCKSTEP_MODULE)
        except ImportError as exc:
            raise RobotUrlError(url, "lockstep", f"the simulation's boards cannot be "
                                f"loaded: {exc}") from exc
    return factory(url, config, options or RobotOptions())
