"""The emergency stop on the wire (docs/protocol.md, "Emergency stop").

Each press puts ESTOP_COPIES EStop frames to each board on the wire at once
(broadcast frames on CAN), sends the unanswered ones again every
ESTOP_RESEND_S, and gives up on a board that has not confirmed (its Status)
within ESTOP_CONFIRM_S.  :func:`press` does that on a link, without waiting
for the lock a read in progress holds; :func:`unconfirmed_text` says what the
host knows of a board that did not confirm.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from stairbot.drivers import messages as m
from stairbot.drivers.link import BoardLink

ESTOP_COPIES = 3
ESTOP_RESEND_S = 0.02
ESTOP_CONFIRM_S = 0.5


@dataclass(frozen=True, slots=True)
class Unconfirmed:
    """The boards that did not confirm an emergency stop, and why."""

    boards: tuple[m.Board, ...]
    why: str


def press(link: BoardLink, lock: threading.RLock,
          monotonic: Callable[[], float] = time.monotonic) -> Unconfirmed | None:
    """Send the emergency stop to every board on ``link`` and wait for each
    board's Status, for at most ESTOP_CONFIRM_S; None once all confirmed.
    ``lock`` is the one a read holds: whoever holds it takes in the replies,
    and when nobody does, this thread does.  Never raises."""
    t0 = monotonic()
    try:
        reqs = link.urgent(m.EStop(), copies=ESTOP_COPIES)
    except Exception as exc:  # noqa: BLE001 - the Robot protocol: estop never raises
        return Unconfirmed(tuple(m.Board), f"cannot send it: {exc}")
    sent = t0
    while True:
        waiting = {r.board for r in reqs} - {r.board for r in reqs if r.reply is not None}
        if not waiting:
            break
        now = monotonic()
        if now - t0 >= ESTOP_CONFIRM_S:
            link.forget(reqs)
            return Unconfirmed(tuple(sorted(m.Board(b) for b in waiting)),
                               f"no Status within {ESTOP_CONFIRM_S * 1e3:.0f} ms of "
                               f"{sum(r.attempts for r in reqs)} EStop frames")
        if now - sent >= ESTOP_RESEND_S:
            sent = now
            # a write that fails: keep trying till the end
            with contextlib.suppress(Exception):
                link.resend_urgent([r for r in reqs if r.board in waiting])
        if lock.acquire(blocking=False):
            try:
                link.poll()
            except Exception:  # noqa: BLE001 - a read that fails is a later read()'s news
                pass
            finally:
                lock.release()
        time.sleep(0.001)
    link.forget(reqs, lost=False)  # the spare copies: their replies count as late
    return None


def unconfirmed_text(boards: Sequence[m.Board], why: str, watchdog_ms: int) -> str:
    """The LINK event's text for boards that did not confirm: what the host
    knows -- not whether a board stopped, only what a working board's
    watchdog (``watchdog_ms``, 0: off) is set to do."""
    names = " and ".join(f"the {b.name.lower()} board" for b in boards)
    watchdog = (f"; this host cannot tell whether it stopped (a board that still runs "
                f"stops its motors {watchdog_ms} ms after it last heard the host)"
                if watchdog_ms else "; the watchdogs are off (watchdog=0)")
    return f"emergency stop not confirmed by {names}: {why}{watchdog}"
