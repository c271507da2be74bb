"""One fake board's lease (docs/protocol.md, section 3, "One host owns the
boards"): which host session holds the board, renewed by every frame of its
holder, taken, renewed or given up by Claim, answered with Owner."""

from __future__ import annotations

from collections.abc import Callable

from stairbot.drivers import messages as m


class Lease:
    """The holder's session and nonce, the lease it asked for, and when its
    last frame came, on ``clock``: a lockstep board's world stands still
    while the host is away, so it counts the lease in wall time; otherwise
    on its own clock.  A lease lasts at least as long as the board's
    watchdog (``watchdog_ms()``).

    ``kept_by_holder`` (lockstep): a lease that lapsed stays its holder's
    until another session claims the board.  Wall time is there only so
    that a host that went away can be replaced; the holder's own frames
    after a pause in wall time -- a loaded machine that did not schedule
    the host or the boards for a second, while the world stood still and
    the watchdog, on the world's clock, did not trip -- renew it, as the
    C boards, whose lockstep clock is the world's, do."""

    def __init__(self, clock: Callable[[], float], watchdog_ms: Callable[[], int],
                 boot: int, kept_by_holder: bool = False) -> None:
        self._clock = clock
        self._watchdog_ms = watchdog_ms
        self.boot = boot  # the board's boot id (Owner.boot)
        self.kept_by_holder = kept_by_holder
        self.owner: int | None = None
        self.owner_nonce = 0
        self.lease_ms = 0
        self._seen = 0.0

    def left_s(self) -> float:
        """How long the lease lasts without another frame from its holder
        (0 when there is none)."""
        if self.owner is None:
            return 0.0
        span = max(self.lease_ms, self._watchdog_ms()) / 1000
        return max(0.0, span - (self._clock() - self._seen))

    def owns(self, session: int) -> bool:
        """Whether ``session`` holds a live lease (or, ``kept_by_holder``,
        one that lapsed and nobody has claimed since)."""
        return self.owner == session and (self.kept_by_holder or self.left_s() > 0)

    def renew(self) -> None:
        """A frame of the holder came now."""
        self._seen = self._clock()

    def reply(self, result: m.ClaimResult) -> m.Owner:
        """The Owner reply saying ``result`` and the lease as it stands."""
        left = self.left_s()
        return m.Owner(int(result), self.owner if left > 0 and self.owner else 0,
                       min(255, round(left * 100)), self.boot)

    def claim(self, msg: m.Claim, session: int) -> m.Owner:
        """Obey a Claim of ``session``: GRANTED (taken or renewed), HELD
        (another host's lease is live), RELEASED or FREE (lease_ms 0)."""
        live = self.left_s() > 0
        if live and (self.owner, self.owner_nonce) != (session, msg.nonce):
            return self.reply(m.ClaimResult.HELD)
        if msg.lease_ms == 0:
            if not live:
                return self.reply(m.ClaimResult.FREE)
            self.owner = None
            return self.reply(m.ClaimResult.RELEASED)
        self.owner, self.owner_nonce, self.lease_ms = session, msg.nonce, msg.lease_ms
        self.renew()
        return self.reply(m.ClaimResult.GRANTED)
