"""The live state of a console that watches another's robot
(console/sharing.py): what the controlling console's hub last sent, aged by
the time since it came, with this console's own notes in the event list."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from stairbot.console.state import CONSOLE, LiveState, StateView


class MirrorState(LiveState):
    """The live state, which while :meth:`watch` is on shows another console's
    (as its hub last sent it, every age grown by the time since) with this
    console's own notes in the event list."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self._watching = ""  # who controls the robot watched ("": this console, no watching)
        self._remote: StateView | None = None
        self._got_at = 0.0
        self._gone = False

    def connected(self) -> None:
        """A connection to a hub was made: what it sends is live."""
        with self._lock:
            self._gone, self._remote = False, None
            self._bump()

    def watch(self, controller: str) -> None:
        """Show what the hub sends, ``controller`` named as who controls the robot."""
        with self._lock:
            self._watching = controller
            self._bump()

    def unwatch(self) -> None:
        """Show this console's own state again."""
        with self._lock:
            self._watching, self._remote, self._gone = "", None, False
            self._bump()

    @property
    def watching(self) -> bool:
        """Another console controls the robot this one shows (and still answers)."""
        with self._lock:
            return bool(self._watching) and not self._gone

    def mirror(self, view: StateView, whole: bool = True) -> None:
        """A copy the controlling console sent: its events (those new since the
        last; its console's own notes left out, they were said to its
        operator), and its graphs' rows when ``whole`` (else the last kept)."""
        for _, event in view.events:
            if event.phase != CONSOLE:
                self.on_event(event)
        with self._lock:
            if not whole and self._remote is not None:
                view = replace(view, history=self._remote.history)
            self._remote, self._got_at = view, self._wall()
            self._bump()

    def lost(self) -> None:
        """The controlling console stopped answering: what it last sent stays, aging."""
        with self._lock:
            self._gone = True
            self._bump()

    def set_robot(self, *args: Any, **kwargs: Any) -> None:
        """This console opens a robot of its own: it no longer watches."""
        self.unwatch()
        super().set_robot(*args, **kwargs)

    def view(self, events_after: int = 0) -> StateView:
        own = super().view(events_after)
        with self._lock:
            remote, got_at, watching, gone = self._remote, self._got_at, self._watching, \
                self._gone
            since = self._wall() - got_at
        if not watching:
            return own
        if remote is None:
            return replace(own, watching=watching)
        status = remote.status
        if gone:
            status = replace(status, severity="warning", message=(
                f"{watching} no longer answers: what it showed last, aging; nothing "
                "here controls the robot (u opens it here)"))
        else:  # its message was for its own operator, whose keys these are not
            status = replace(status, message=(
                f"watching: {watching} controls this robot; h asks for control"
                + (f" · there: {status.message}" if status.message else "")))
        return replace(
            remote, version=own.version, events=own.events, status=status,
            read_age_s=None if remote.read_age_s is None else remote.read_age_s + since,
            top_age_s=None if remote.top_age_s is None else remote.top_age_s + since,
            watching=watching + (" (gone)" if gone else ""))
