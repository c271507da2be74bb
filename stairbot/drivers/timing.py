"""How long the host waits for the boards, against how long their watchdogs
wait for the host (docs/protocol.md, "Riding through noise in real time").

A board's watchdog is fed by every valid frame addressed to it.  While a
read waits for a reply, the host sends its request again every ``timeout``,
and each such round sends every board a Heartbeat too
(``request_link.py``), so a board that lost a request hears the next
round's two frames one ``timeout`` later.  The board last heard the host
at most one control tick before the read began (the previous cycle's
frames).  Every attempt of one request lost, the
first frame after them -- the query sent again within the grace period --
reaches the board ``tick + attempts * timeout`` after it was last fed; it
must come before the watchdog runs out::

    (retries + 1) * timeout  <  watchdog - tick

so that a board misses ``retries + 1`` attempts in a row and still hears
the next one in time; an attempt after the first is lost only when both of
its round's frames are.  A URL whose options break this is refused
(RobotUrlError, one line naming the options and what is allowed); nothing is clamped behind
the operator's back.  It does not apply in lockstep, where the boards'
clock stands still while the host waits, nor with the watchdog off.

``timeout``, ``grace`` and ``watchdog`` are times of the robot's clock: wall
time, or for fake boards paced at ``time_scale`` X times real time, X times
faster.  Such boards count their watchdog in simulated time, so the host
waits ``timeout / X`` and ``grace / X`` of wall time: a time-scaled run is
the real-time run played faster, its watchdog no more lenient.
"""

from __future__ import annotations

from dataclasses import dataclass

from stairbot.errors import RobotUrlError


@dataclass(frozen=True)
class LinkTiming:
    """A link's waits in wall seconds (what the link's clock counts)."""

    timeout_s: float
    grace_s: float


def budget_s(watchdog_ms: float, tick_s: float) -> float:
    """The seconds every attempt of one request may take together: the
    watchdog less one control tick."""
    return watchdog_ms / 1000 - tick_s


def check_ride_through(url: str, options: dict[str, float], tick_s: float) -> None:
    """RobotUrlError unless ``(retries + 1) * timeout < watchdog - tick``
    (module docstring), naming the options, their values and what is
    allowed.  Lockstep and ``watchdog=0`` are exempt."""
    watchdog = options["watchdog"]
    if options.get("lockstep") or not watchdog:
        return
    attempts = int(options["retries"]) + 1
    timeout = options["timeout"]
    budget = budget_s(watchdog, tick_s)
    if attempts * timeout < budget:
        return
    if budget <= 0:
        raise RobotUrlError(url, "watchdog", f"{watchdog:g} ms leaves nothing for retries "
                            f"after one control tick ({tick_s * 1e3:g} ms); allowed: above "
                            f"{tick_s * 1e3:g} ms, or 0 (off)")
    raise RobotUrlError(
        url, "timeout, retries, watchdog",
        f"(retries + 1) x timeout = {attempts} x {timeout * 1e3:g} ms = "
        f"{attempts * timeout * 1e3:g} ms must be below watchdog - one tick = "
        f"{watchdog:g} - {tick_s * 1e3:g} ms = {budget * 1e3:g} ms, or a board whose frames "
        f"are lost trips its watchdog while the host still retries; allowed here: timeout "
        f"below {budget / attempts * 1e3:.4g} ms with retries={attempts - 1}, fewer retries, "
        "or a longer watchdog")


def link_timing(options: dict[str, float], time_scale: float) -> LinkTiming:
    """The link's waits in wall seconds for boards paced at ``time_scale``."""
    if options.get("lockstep"):
        return LinkTiming(options["timeout"], options["grace"])
    return LinkTiming(options["timeout"] / time_scale, options["grace"] / time_scale)
