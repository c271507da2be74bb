"""What a lost link means for the motors, as the host can tell it.

A host that loses its link to the boards says what became of the motors:
stopped by the boards (a tripped watchdog), stopped by this host's own
emergency stop (a failed wire latches it), or left to the boards' watchdogs
-- and, with them off, possibly still running.  What it cannot know it does
not say: whether the boards are alive, and so whether their watchdogs have
stopped anything.
"""

from __future__ import annotations


def consequence(watchdog_ms: int, *, latch: bool, boards_stopped: bool) -> str:
    """The tail of a LinkLostError's text (empty, or starting "; "): what
    became of the motors.  ``latch``: this host latched its emergency stop
    (a failed wire); ``boards_stopped``: a board said it stopped them."""
    if latch:
        return ("; this host's emergency stop is latched (EStop frames sent; a board "
                "that did not hear them stops its motors when its watchdog runs out)")
    if boards_stopped:
        return ""
    if watchdog_ms:
        return (f"; a board that hears nothing more stops its motors when its "
                f"watchdog ({watchdog_ms} ms) runs out")
    return "; the boards' watchdogs are off (watchdog=0): motors may still run"
