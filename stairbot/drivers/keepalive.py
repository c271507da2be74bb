"""A robot's keepalive: a daemon thread that keeps its boards' watchdogs fed
and its leases live while the robot stands idle (a console before its run
starts, an operator asked to confirm), when no control loop sends frames."""

from __future__ import annotations

import threading
from collections.abc import Callable


class Keepalive:
    """Calls ``beat`` every ``period()`` seconds (asked again before each
    wait) on a daemon thread named ``name``, until :meth:`stop` or until
    ``beat`` returns False.  An exception ``beat`` raises is dropped: link
    trouble shows on the robot's next read."""

    def __init__(self, name: str, period: Callable[[], float],
                 beat: Callable[[], bool]) -> None:
        self._period = period
        self._beat = beat
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True, name=name)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(self._period()):
            try:
                if not self._beat():
                    return
            except Exception:  # noqa: BLE001 - link trouble shows on the next read()
                continue

    def stop(self, join_s: float = 1.0) -> None:
        """Stop the thread, and wait up to ``join_s`` for it (unless called from it)."""
        self._stop.set()
        if self._thread is not threading.current_thread():
            self._thread.join(join_s)
