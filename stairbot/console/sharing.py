"""One console controls a robot; others on this machine watch it.

A console that opens a robot on a locked URL (a serial port, a CAN bus:
``drivers/port_lock.py``) shares what it shows: a :class:`ShareHub` listens on
a Unix socket named after the robot's lock file and sends each console that
connects a copy of its live state ten times a second.  A second console on
the same robot -- a second browser tab of ``stairbot console --serve``, or a
second terminal -- finds the port locked and, when a hub answers there,
watches instead of being refused: :class:`MirrorState` shows the first
console's state read-only, every value aged by the time since it came.  A
watching console's emergency stop goes to the controlling console, which
latches it; control passes only when the controlling console's operator
hands it over, and never during a run.

A connection must prove it read the hub's key -- a file only this user can
read (mode 0600, in the lock directory, 0700), new each time a hub starts --
by ``multiprocessing.connection``'s HMAC challenge before anything is sent
either way.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import socket
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from multiprocessing.connection import Client, Connection, Listener
from multiprocessing.context import AuthenticationError
from pathlib import Path
from typing import Any

from stairbot.console.state import LiveState, StateView
from stairbot.drivers.robot_lock import robot_lock_path

SEND_PERIOD_S = 0.1
"""Seconds between copies sent to a watching console (the screen's own rate)."""
KEY_BYTES = 32


@dataclass(frozen=True)
class ShareAddress:
    """Where a console shares its robot: a Unix socket (on Linux in the
    abstract namespace: no file to leave behind, and no path too long for a
    socket) and the key a console must prove it read (a file only this user
    can read)."""

    socket: str
    key: Path


def share_address(url: str) -> ShareAddress | None:
    """Where the console that has ``url`` open shares it (None: no lock
    guards that robot, so no other console can be kept from it)."""
    lock = robot_lock_path(url)
    if lock is None:
        return None
    digest = hashlib.sha256(str(lock).encode()).hexdigest()[:24]
    name = f"share-{digest}"
    socket = f"\0stairbot-{os.getuid()}-{name}" if sys.platform == "linux" \
        else str(lock.parent / f"{name}.sock")
    return ShareAddress(socket, lock.parent / f"{name}.key")


def whoami() -> str:
    """This console, as the other console's operator reads it."""
    return f"the console with pid {os.getpid()}"


Reply = Callable[[bool, str], None]
"""Answers a request for control: (granted, why)."""


class ShareHub:
    """Sends ``state`` to every console that connects at ``address``; passes
    their requests on: ``on_estop(who) -> what was done`` and
    ``on_ask(who, reply)`` (``reply`` may be called from any thread, once)."""

    def __init__(self, address: ShareAddress, state: LiveState, *,
                 on_estop: Callable[[str], str], on_ask: Callable[[str, Reply], None],
                 period_s: float = SEND_PERIOD_S) -> None:
        self.address = address
        self._state = state
        self._on_estop, self._on_ask = on_estop, on_ask
        self._period_s = period_s
        self._closed = threading.Event()
        self._conns: list[Connection] = []
        self._lock = threading.Lock()
        key = os.urandom(KEY_BYTES)
        address.key.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
        # The caller holds the robot's lock: files left here are a dead console's.
        address.key.unlink(missing_ok=True)
        fd = os.open(address.key, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "wb") as out:
            out.write(key)
        if not address.socket.startswith("\0"):
            Path(address.socket).unlink(missing_ok=True)
        self._listener = Listener(address.socket, family="AF_UNIX", authkey=key)
        if not address.socket.startswith("\0"):
            os.chmod(address.socket, 0o600)
        self._acceptor = threading.Thread(target=self._accept, name="share hub", daemon=True)
        self._acceptor.start()

    def _accept(self) -> None:
        while not self._closed.is_set():
            try:
                conn = self._listener.accept()
            except (AuthenticationError, EOFError, ConnectionError):
                continue  # a client that did not prove it read the key (or close()'s wake-up)
            except OSError:
                return  # closed
            with self._lock:
                if self._closed.is_set():
                    conn.close()
                    return
                self._conns.append(conn)
            threading.Thread(target=self._serve, args=(conn,), name="share viewer",
                             daemon=True).start()

    def _serve(self, conn: Connection) -> None:
        sent = 0  # the last event sent
        send_lock = threading.Lock()

        def send(message: tuple[Any, ...]) -> None:
            with send_lock:
                conn.send(message)

        try:
            while not self._closed.is_set():
                view = self._state.view(events_after=sent)
                if view.events:
                    sent = view.events[-1][0]
                send(("view", view))
                deadline = time.monotonic() + self._period_s
                while (left := deadline - time.monotonic()) > 0 and conn.poll(left):
                    self._handle(conn.recv(), send)
        except (OSError, EOFError):
            pass  # the watching console went, or this hub closed
        finally:
            with self._lock:
                if conn in self._conns:
                    self._conns.remove(conn)
            conn.close()

    def _handle(self, message: Any, send: Callable[[tuple[Any, ...]], None]) -> None:
        if not isinstance(message, tuple) or not message:
            return
        kind, who = message[0], str(message[1]) if len(message) > 1 else "a watching console"
        if kind == "estop":
            send(("said", self._on_estop(who), "warning"))
        elif kind == "ask":
            answered = threading.Event()

            def reply(granted: bool, why: str) -> None:
                if answered.is_set():
                    return
                answered.set()
                with contextlib.suppress(OSError):
                    send(("granted" if granted else "refused", why))
            self._on_ask(who, reply)

    def close(self) -> None:
        """Stop sharing: the watching consoles are told the connection ended."""
        if self._closed.is_set():
            return
        self._closed.set()
        # A socket closed while accept() waits on it stays bound until accept
        # returns: wake it with a connection first, so the address is free
        # for the next console at once.
        with contextlib.suppress(OSError), socket.socket(socket.AF_UNIX) as wake:
            wake.connect(self.address.socket)
        self._acceptor.join(timeout=2.0)
        with contextlib.suppress(OSError):
            self._listener.close()
        with self._lock:
            conns, self._conns = self._conns, []
        for conn in conns:
            with contextlib.suppress(OSError):
                conn.close()
        paths = [self.address.key]
        if not self.address.socket.startswith("\0"):
            paths.append(Path(self.address.socket))
        for path in paths:
            with contextlib.suppress(OSError):
                path.unlink()


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

    def watch(self, controller: str) -> None:
        """Show what the hub sends (the copies that came since the client
        connected included), ``controller`` named as who controls the robot."""
        with self._lock:
            self._watching, self._gone = controller, False
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

    def mirror(self, view: StateView) -> None:
        """A copy the controlling console sent (its events: those new since the last)."""
        for _, event in view.events:
            self.on_event(event)
        with self._lock:
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
        if not status.message:
            status = replace(status, severity="info", message=(
                f"watching: {watching} controls this robot; h asks for control"))
        if gone:
            status = replace(status, severity="warning", message=(
                f"{watching} no longer answers: what it showed last, aging; nothing "
                "here controls the robot (u opens it here)"))
        return replace(
            remote, version=own.version, events=own.events, status=status,
            read_age_s=None if remote.read_age_s is None else remote.read_age_s + since,
            top_age_s=None if remote.top_age_s is None else remote.top_age_s + since,
            watching=watching + (" (gone)" if gone else ""))


class ShareClient:
    """A watching console's connection to the hub at ``address``: its copies go
    to ``state``; what the controlling console says back goes to
    ``on_reply(kind, text, severity)`` (kind: "said", "granted", "refused",
    "gone"), on the connection's own thread."""

    def __init__(self, address: ShareAddress, state: MirrorState,
                 on_reply: Callable[[str, str, str], None]) -> None:
        key = address.key.read_bytes()  # OSError: no console shares there
        self._conn = Client(address.socket, family="AF_UNIX", authkey=key)
        self._state = state
        self._on_reply = on_reply
        self._send_lock = threading.Lock()
        self._closed = threading.Event()
        threading.Thread(target=self._receive, name="share client", daemon=True).start()

    def _receive(self) -> None:
        try:
            while True:
                message = self._conn.recv()
                kind = message[0]
                if kind == "view":
                    self._state.mirror(message[1])
                elif kind == "said":
                    self._on_reply("said", str(message[1]), str(message[2]))
                elif kind in ("granted", "refused"):
                    self._on_reply(kind, str(message[1]), "information")
        except (OSError, EOFError, TypeError, ValueError):
            pass  # the hub closed, or this end did (close() from another thread)
        if not self._closed.is_set():
            self._state.lost()
            self._on_reply("gone", "the controlling console closed", "warning")

    def send(self, kind: str) -> bool:
        """Send a request ("estop", "ask"); False when the hub no longer answers."""
        try:
            with self._send_lock:
                self._conn.send((kind, whoami()))
        except (OSError, ValueError):
            return False
        return True

    def close(self) -> None:
        self._closed.set()
        with contextlib.suppress(OSError):
            self._conn.close()


def connect(url: str, state: MirrorState,
            on_reply: Callable[[str, str, str], None]) -> ShareClient | None:
    """Watch the console that has ``url`` open (None: none shares it here)."""
    address = share_address(url)
    if address is None:
        return None
    try:
        return ShareClient(address, state, on_reply)
    except (OSError, EOFError, AuthenticationError):
        return None
