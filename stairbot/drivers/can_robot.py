"""The robot on a CAN bus, through any python-can interface.

URL format: ``can://INTERFACE/CHANNEL[?option=value[&option=value...]]``

* ``INTERFACE`` -- a python-can interface name (``virtual``, ``udp_multicast``,
  ``socketcan``, ``slcan``, ``pcan``, ...).  ``default`` or empty takes it
  from python-can's own configuration: ``can.rc``, the ``CAN_INTERFACE``
  environment variable, ``~/.canrc`` / ``~/.can`` / ``/etc/can.conf``.
* ``CHANNEL`` -- the rest of the path, percent-decoded, handed to python-can
  as it is: ``vcan0``, ``bus0``, ``PCAN_USBBUS1``, a multicast group for
  ``udp_multicast`` (``239.74.163.2`` or ``ff15::1``), a device path for
  ``slcan`` (``can://slcan//dev/ttyACM0``).  Empty: from the configuration
  (``CAN_CHANNEL``...), else the interface's own default.
* options (the rest, like ``serial://``):

  - ``bitrate=N``     bit/s, given to the interface (else ``CAN_BITRATE``...)
  - ``context=NAME``  the section of python-can's config file to read
  - ``timeout=S``     seconds to wait for a board's replies, default 0.05;
                      0 < S <= 60; (retries + 1) x timeout must be below
                      watchdog - one tick (``timing.py``), else refused
  - ``retries=N``     re-sends of a query that timed out, default 2; 0 to 100
  - ``lost=N``        unanswered commands in a row that mean the link is
                      lost (once the grace period is over), default 3; 1 to
                      1000
  - ``grace=S``       seconds a board may stay silent before the link is
                      lost, default 0.5: until then a query that got no
                      reply after its retries is sent again; 0 = lost at the
                      first query given up; at most 60
  - ``watchdog=MS``   the boards' watchdog in ms of the robot's clock, set
                      at open, default 250 (0 = off), at most 65535
  - ``lockstep=1``    simulation only: the fake boards' world advances only
                      when the host's clock sends StepTo, once per tick
                      (``stairbot.fakes.lockstep`` opens such boards)
  - ``time_scale=X``  simulation only: the fake boards run X times real time;
                      the host's clock runs at the same rate, and timeout,
                      grace and watchdog are times of that clock (the host
                      waits timeout / X of wall time); 0.01 to 1000
  - ``lan=1``         ``udp_multicast`` only: open the bus to the network
                      (python-can's own socket: see below).  Default 0.
  - ``log=FILE``      write every frame sent and received to FILE with
                      python-can's writer for its extension: ``.log`` candump
                      (``cantools decode -m 0x1FFC0000 stairbot.dbc`` reads
                      it), ``.asc``, ``.trc``, ``.csv``; flushed as written
                      (``frame_log.py``)
  - any other ``key=value`` is passed to ``can.Bus`` as a keyword, its value
    cast as python-can casts its config files (``port=43200``,
    ``receive_own_messages=False``).

``udp_multicast`` is kept on this machine's loopback interface
(``drivers.udp_loopback``): its socket is bound to ``GROUP:PORT`` (not
``0.0.0.0``), joins the group on ``127.0.0.1`` only and sends out of
``127.0.0.1`` with TTL (``hop_limit``) 0, so only processes on this machine
can send it frames or hear them.  It takes IPv4 groups only (Linux carries no
IPv6 multicast over loopback).  ``lan=1`` instead opens python-can's own
socket, bound to ``0.0.0.0:PORT`` (``[::]:PORT``), joined on the interface the
routing table picks and sending with python-can's ``hop_limit`` 1 unless the
URL gives one: then any host on that network can send frames to the boards
or the host (make them stop, or move).  Use a different ``port=`` to keep two
buses on one group apart.

One stairbot host on a bus at a time on this machine: opening takes a lock
per interface and channel (``port_lock.py``; a second host is refused with
one PortBusyError line naming the process that holds it), released when the
bus shuts down.  Hosts on other machines are kept off by the boards' lease
(docs/protocol.md, "One host owns the boards").

Examples::

    can://virtual/bus0
    can://udp_multicast/239.74.163.2?port=43114&lockstep=1
    can://udp_multicast/ff15::1?lan=1     (on the LAN, IPv6: anyone there can send frames)
    can://socketcan/vcan0?bitrate=1000000
    can://default/                      (everything from python-can's config)
"""

from __future__ import annotations

import ipaddress
import os
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import unquote

import can
import can.util

from stairbot.drivers.board_session import open_board_session, wanted_side_pair
from stairbot.drivers.can_link import CanLink
from stairbot.drivers.frame_log import CanFrameLog, check_can_log
from stairbot.drivers.port_lock import PortLock, take_port_lock
from stairbot.drivers.timing import check_ride_through, link_timing
from stairbot.drivers.udp_loopback import LoopbackUdpMulticastBus
from stairbot.drivers.url_options import number_option, query_pairs
from stairbot.errors import RobotUrlError
from stairbot.inputs.config import RobotConfig
from stairbot.run.robots import RobotOptions, RobotSession

OPTION_DEFAULTS: dict[str, float] = {
    "timeout": 0.05, "retries": 2, "lost": 3, "watchdog": 250, "lockstep": 0, "time_scale": 1.0,
    "lan": 0, "grace": 0.5,
}


@dataclass(frozen=True)
class CanUrl:
    """A parsed ``can://`` URL: how to open the bus, and the driver's own options."""

    url: str
    interface: str | None
    channel: str | None
    bus_kwargs: dict[str, Any] = field(default_factory=dict)
    context: str | None = None
    options: dict[str, float] = field(default_factory=lambda: dict(OPTION_DEFAULTS))
    log: str | None = None  # the frame log's path

    @property
    def label(self) -> str:
        """``INTERFACE/CHANNEL`` as given (``default`` where left to the config)."""
        return f"{self.interface or 'default'}/{self.channel or ''}"


def parse_can_url(url: str) -> CanUrl:
    """Split a ``can://`` URL (grammar in the module header) without opening
    anything.  Raises RobotUrlError naming the bad part and what is allowed."""
    if not url.startswith("can://"):
        raise RobotUrlError(url, None, "not a CAN URL; expected can://INTERFACE/CHANNEL?...")
    rest, _, query = url[len("can://"):].partition("?")
    iface_text, _, channel_text = rest.partition("/")
    interface = unquote(iface_text).strip() or None
    if interface == "default":
        interface = None
    if interface is not None and interface not in can.VALID_INTERFACES:
        allowed = ", ".join(sorted(can.VALID_INTERFACES))
        raise RobotUrlError(url, "interface", f"unknown python-can interface {interface!r}; "
                            f"allowed: {allowed}, or default")
    channel = unquote(channel_text) or None
    kwargs: dict[str, Any] = {}
    options = dict(OPTION_DEFAULTS)
    context: str | None = None
    log: str | None = None
    for key, value in query_pairs(url, query):
        if key in OPTION_DEFAULTS:
            options[key] = number_option(url, key, value)
        elif key == "log":
            check_can_log(url, value)
            log = value
        elif key == "context":
            context = value or None
        elif key in ("interface", "bustype", "channel"):
            raise RobotUrlError(url, key, "give the interface and channel in the path: "
                                "can://INTERFACE/CHANNEL")
        else:
            kwargs[key] = can.util.cast_from_string(value)
    if "bitrate" in kwargs and not (isinstance(kwargs["bitrate"], int) and kwargs["bitrate"] > 0):
        raise RobotUrlError(url, "bitrate", f"{kwargs['bitrate']!r} is not a positive "
                            "whole number of bit/s")
    lan = bool(options["lan"])
    if lan and interface not in (None, "udp_multicast"):
        raise RobotUrlError(url, "lan", f"applies to udp_multicast only, not {interface}")
    if interface == "udp_multicast" and channel is not None:
        _check_multicast(url, channel, lan)
    return CanUrl(url, interface, channel, kwargs, context, options, log)


def _check_multicast(url: str, channel: str, lan: bool) -> None:
    try:
        addr = ipaddress.ip_address(channel)
    except ValueError as exc:
        raise RobotUrlError(url, "channel", f"udp_multicast needs a multicast group address "
                            f"as the channel, e.g. 239.74.163.2 or ff15::1; got {channel!r}"
                            ) from exc
    if not addr.is_multicast:
        raise RobotUrlError(url, "channel", f"{channel} is not a multicast group; allowed: "
                            "224.0.0.0/4 (IPv4) or ff00::/8 (IPv6)")
    if addr.version == 6 and not lan:
        raise RobotUrlError(url, "channel", f"{channel} is an IPv6 group, and udp_multicast is "
                            "kept on the loopback interface, which carries IPv4 multicast only; "
                            "allowed: an IPv4 group (224.0.0.0/4, e.g. 239.74.163.2), or lan=1 "
                            "to open the bus to the network")


def resolve_bus_config(spec: CanUrl) -> dict[str, Any]:
    """The bus settings python-can would use for ``spec``: the URL first, then
    python-can's config (``can.rc``, ``CAN_*`` variables, config files).
    Raises RobotUrlError when no interface is named anywhere."""
    given: dict[str, Any] = dict(spec.bus_kwargs)
    if spec.interface is not None:
        given["interface"] = spec.interface
    if spec.channel is not None:
        given["channel"] = spec.channel
    try:
        resolved: dict[str, Any] = dict(can.util.load_config(config=given, context=spec.context))
    except can.CanInterfaceNotImplementedError as exc:
        what = str(exc) if spec.interface else "no CAN interface given"
        raise RobotUrlError(spec.url, "interface", f"{what}; name one in the URL "
                            "(can://virtual/bus0) or in python-can's config "
                            "(CAN_INTERFACE, ~/.canrc)") from exc
    except Exception as exc:  # a malformed config file or CAN_CONFIG
        raise RobotUrlError(spec.url, "python-can config", f"{type(exc).__name__}: {exc}") from exc
    lan = bool(spec.options["lan"])
    if resolved.get("interface") == "udp_multicast":
        if resolved.get("channel") is not None:
            _check_multicast(spec.url, str(resolved["channel"]), lan)
        if not lan:
            resolved.setdefault("hop_limit", 0)
        resolved.setdefault("fd", False)
    elif lan:
        raise RobotUrlError(spec.url, "lan", "applies to udp_multicast only, not "
                            f"{resolved.get('interface')}")
    return resolved


def keeps_to_loopback(spec: CanUrl, cfg: dict[str, Any]) -> bool:
    """Whether the bus ``cfg`` (from :func:`resolve_bus_config`) is opened on
    the loopback interface only: ``udp_multicast`` without ``lan=1``."""
    return cfg.get("interface") == "udp_multicast" and not spec.options["lan"]


def open_bus(spec: CanUrl) -> can.BusABC:
    """Open the bus ``spec`` names (``udp_multicast``: on loopback unless
    ``lan=1``; the module header).  Any failure of the interface (missing
    driver library, device absent, address family unsupported) becomes one
    RobotUrlError line naming the interface and channel."""
    cfg = resolve_bus_config(spec)
    where = f"{cfg.get('interface')}/{cfg.get('channel') if cfg.get('channel') is not None else ''}"
    try:
        if keeps_to_loopback(spec, cfg):
            kwargs = {k: v for k, v in cfg.items()
                      if k != "interface" and not (k == "channel" and v is None)}
            return LoopbackUdpMulticastBus(**kwargs)
        return can.Bus(ignore_config=True, **cfg)
    except Exception as exc:  # vendor back ends raise anything: OSError, NameError...
        detail = str(exc).strip() or type(exc).__name__
        raise RobotUrlError(spec.url, None, f"cannot open CAN bus {where}: {detail}") from exc


def bus_lock_key(spec: CanUrl) -> tuple[str, str]:
    """(the key of the lock on ``spec``'s bus, the bus as a message names it:
    ``udp_multicast/239.74.163.2``).  RobotUrlError when no interface is named."""
    cfg = resolve_bus_config(spec)
    where = f"{cfg.get('interface')}/{cfg.get('channel') if cfg.get('channel') is not None else ''}"
    return f"can:{where}" + (f"@pid{os.getpid()}" if cfg.get("interface") == "virtual"
                             else ""), where


def lock_bus(spec: CanUrl) -> PortLock:
    """This machine's lock on the bus ``spec`` names (``port_lock.py``): one
    stairbot host on a bus at a time.  A python-can ``virtual`` bus does not
    leave its process (two processes on one channel name are two buses), so
    its lock is this process's own, as ``loop://``'s would be.  PortBusyError
    names the holder; RobotUrlError when the lock file cannot be made."""
    key, where = bus_lock_key(spec)
    try:
        return take_port_lock(key, f"CAN bus {where}")
    except OSError as exc:
        raise RobotUrlError(spec.url, None, f"cannot lock CAN bus {where}: "
                            f"{exc.strerror or exc}") from None


def open_can_robot(url: str, config: RobotConfig, options: RobotOptions) -> RobotSession:
    """Open ``can://INTERFACE/CHANNEL?...``: both boards on one bus, driven by
    ``board_robot.BoardRobot`` over a :class:`CanLink` (an emergency stop is
    one broadcast frame with the bus's highest-priority id).  RobotUrlError
    (one line) when the URL is malformed or the bus cannot open; NoBoardError
    (a HardwareError, one line naming the board and the URL) when no board
    answers."""
    spec = parse_can_url(url)
    opts = spec.options
    check_ride_through(url, opts, config.algorithm.tick)
    lock = lock_bus(spec)
    try:
        bus = open_bus(spec)
    except BaseException:
        lock.release()
        raise
    try:
        log = CanFrameLog(url, spec.log) if spec.log else None
    except RobotUrlError:
        try:
            bus.shutdown()
        finally:
            lock.release()
        raise
    time_scale = options.time_scale or opts["time_scale"]
    timing = link_timing(opts, time_scale)
    link = CanLink(bus, timeout_s=timing.timeout_s, retries=int(opts["retries"]),
                   max_lost=int(opts["lost"]), grace_s=timing.grace_s, log=log,
                   on_close=lock.release)
    return open_board_session(link, url, watchdog_ms=int(opts["watchdog"]),
                              lockstep=bool(opts["lockstep"]),
                              time_scale=time_scale,
                              allow_latched=options.allow_latched,
                              side_pair=wanted_side_pair(config))
