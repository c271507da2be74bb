"""One console controls a robot; others on this machine watch it.

A console that opens a robot on a locked URL (a serial port, a CAN bus:
``drivers/port_lock.py``) shares what it shows: a :class:`ShareHub` listens on
a Unix socket named after the robot's lock file and sends each console that
connects a copy of its live state ten times a second.  A second console on
the same robot -- a second browser tab of ``stairbot console --serve``, or a
second terminal -- finds the port locked and, when a hub answers there,
watches instead of being refused: ``console/mirror.py``'s MirrorState shows the first
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
import queue
import socket
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from multiprocessing.connection import (
    Connection,
    Listener,
    answer_challenge,
    deliver_challenge,
)
from pathlib import Path
from typing import Any

from stairbot.console.mirror import MirrorState
from stairbot.console.state import LiveState
from stairbot.drivers.robot_lock import robot_lock_path

SEND_PERIOD_S = 0.1
"""Seconds between copies sent to a watching console (the screen's own rate)."""
HISTORY_EVERY = 10
"""The graphs' rows (30 s of readings, most of a copy's size) go with every
tenth copy; the watching console keeps the last it got in between."""
OUTBOX_POLL_S = 0.02
"""How often a hub's thread looks for answers to send while it waits."""
CONNECT_TIMEOUT_S = 3.0
"""How long a console waits for a hub to answer and prove its key."""
CLOSE_GRACE_S = 0.5
"""How long a closing hub lets its watchers' threads send what is left."""
SOCKET_PATH_MAX = 100
"""A Unix socket's path longer than this (sun_path holds 108 bytes) is named
in Linux's abstract namespace instead."""
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
    path = lock.parent / f"{name}.sock"  # in the user's own directory (0700)
    socket_name = str(path) if len(str(path)) < SOCKET_PATH_MAX or sys.platform != "linux" \
        else f"\0stairbot-{os.getuid()}-{name}"
    return ShareAddress(socket_name, lock.parent / f"{name}.key")


def whoami() -> str:
    """This console, as the other console's operator reads it."""
    return f"the console with pid {os.getpid()}"


class Request:
    """A watching console's request for control, answered once (from any
    thread: the answer is sent on the hub's own thread)."""

    def __init__(self, who: str, outbox: queue.SimpleQueue[tuple[Any, ...]],
                 gone: threading.Event) -> None:
        self.who = who
        self._outbox = outbox
        self._gone = gone
        self._answered = threading.Event()

    @property
    def alive(self) -> bool:
        """The console that asked is still connected."""
        return not self._gone.is_set()

    def answer(self, granted: bool, why: str) -> None:
        if not self._answered.is_set():
            self._answered.set()
            self._outbox.put(("granted" if granted else "refused", why))


class ShareHub:
    """Sends ``state`` to every console that connects at ``address`` and
    proves it read the key; passes their requests on: ``on_estop(who) ->
    what was done`` and ``on_ask(request)``.  Each watching console has a
    thread of its own, which alone sends to it: a console that stops reading
    holds up nothing else."""

    def __init__(self, address: ShareAddress, state: LiveState, *,
                 on_estop: Callable[[str], str], on_ask: Callable[[Request], None],
                 period_s: float = SEND_PERIOD_S) -> None:
        self.address = address
        self._state = state
        self._on_estop, self._on_ask = on_estop, on_ask
        self._period_s = period_s
        self._closed = threading.Event()
        self._conns: list[Connection] = []
        self._lock = threading.Lock()
        self._key = os.urandom(KEY_BYTES)
        address.key.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
        # The caller holds the robot's lock: files left here are a dead console's.
        address.key.unlink(missing_ok=True)
        fd = os.open(address.key, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "wb") as out:
            out.write(self._key)
        if not address.socket.startswith("\0"):
            Path(address.socket).unlink(missing_ok=True)
        self._listener = Listener(address.socket, family="AF_UNIX")
        self._acceptor = threading.Thread(target=self._accept, name="share hub", daemon=True)
        self._acceptor.start()

    def _accept(self) -> None:
        while not self._closed.is_set():
            try:
                conn = self._listener.accept()
            except OSError:
                if self._closed.is_set():
                    return
                continue
            with self._lock:
                if self._closed.is_set():
                    conn.close()
                    return
                self._conns.append(conn)
            threading.Thread(target=self._serve, args=(conn,), name="share viewer",
                             daemon=True).start()

    def _serve(self, conn: Connection) -> None:
        outbox: queue.SimpleQueue[tuple[Any, ...]] = queue.SimpleQueue()
        gone = threading.Event()
        sent = 0  # the last event sent
        count = 0
        try:
            # the key's proof, both ways, here: a client that stalls or lies
            # holds up its own thread alone
            deliver_challenge(conn, self._key)
            answer_challenge(conn, self._key)
            while not self._closed.is_set():
                view = self._state.view(events_after=sent)
                if view.events:
                    sent = view.events[-1][0]
                whole = count % HISTORY_EVERY == 0  # the graphs' rows: once a second
                count += 1
                conn.send(("view", view if whole else replace(view, history=()), whole))
                deadline = time.monotonic() + self._period_s
                while (left := deadline - time.monotonic()) > 0:
                    while not outbox.empty():
                        conn.send(outbox.get())
                    if conn.poll(min(left, OUTBOX_POLL_S)):
                        self._handle(conn.recv(), outbox, gone)
            while not outbox.empty():  # answers given as the hub closed (control handed over)
                conn.send(outbox.get())
        except Exception:  # noqa: BLE001 - any failure ends this watcher's connection alone
            pass
        finally:
            gone.set()
            with self._lock:
                if conn in self._conns:
                    self._conns.remove(conn)
            with contextlib.suppress(OSError):
                conn.close()

    def _handle(self, message: Any, outbox: queue.SimpleQueue[tuple[Any, ...]],
                gone: threading.Event) -> None:
        if not isinstance(message, tuple) or not message:
            return
        kind, who = message[0], str(message[1]) if len(message) > 1 else "a watching console"
        if kind == "estop":
            outbox.put(("said", self._on_estop(who), "warning"))
        elif kind == "ask":
            self._on_ask(Request(who, outbox, gone))

    def close(self) -> None:
        """Stop sharing: the watching consoles are told the connection ended."""
        if self._closed.is_set():
            return
        self._closed.set()
        # the key file only if it is still this hub's (a console that took
        # control over may have started its own by now)
        with contextlib.suppress(OSError):
            if self.address.key.read_bytes() == self._key:
                self.address.key.unlink()
        # A socket closed while accept() waits on it stays bound until accept
        # returns: wake it with a connection first, so the address is free
        # for the next console at once.
        with contextlib.suppress(OSError), socket.socket(socket.AF_UNIX) as wake:
            wake.settimeout(1.0)
            wake.connect(self.address.socket)
        self._acceptor.join(timeout=2.0)
        with contextlib.suppress(OSError):
            self._listener.close()
        # each watcher's thread sends what is left for it and closes its end;
        # one that cannot (a watcher that stopped reading) is cut off
        deadline = time.monotonic() + CLOSE_GRACE_S
        while time.monotonic() < deadline:
            with self._lock:
                if not self._conns:
                    break
            time.sleep(OUTBOX_POLL_S)
        with self._lock:
            conns, self._conns = self._conns, []
        for conn in conns:
            with contextlib.suppress(OSError):
                conn.close()
        if not self.address.socket.startswith("\0"):
            with contextlib.suppress(OSError):
                Path(self.address.socket).unlink()


def _open_connection(address: ShareAddress, key: bytes) -> Connection:
    """A connection to the hub at ``address`` that proved, both ways, it read
    ``key``; OSError when none answers, or none proves it within
    CONNECT_TIMEOUT_S (a hub that stalls is no hub)."""
    sock = socket.socket(socket.AF_UNIX)
    try:
        sock.settimeout(CONNECT_TIMEOUT_S)
        sock.connect(address.socket)
        sock.setblocking(True)
    except BaseException:
        sock.close()
        raise
    conn = Connection(sock.detach())
    done, failed = threading.Event(), threading.Event()

    def prove() -> None:
        try:
            answer_challenge(conn, key)
            deliver_challenge(conn, key)
        except Exception:  # noqa: BLE001 - any failure: no hub here
            failed.set()
        finally:
            done.set()

    threading.Thread(target=prove, name="share proof", daemon=True).start()
    if not done.wait(CONNECT_TIMEOUT_S) or failed.is_set():
        with contextlib.suppress(OSError):
            conn.close()
        raise OSError(f"the console sharing at {address.socket!r} did not prove its key")
    return conn


class ShareClient:
    """A watching console's connection to the hub at ``address``: its copies go
    to ``state``; what the controlling console says back goes to
    ``on_reply(kind, text, severity)`` (kind: "said", "granted", "refused",
    "gone"), on the connection's own thread."""

    def __init__(self, address: ShareAddress, state: MirrorState,
                 on_reply: Callable[[str, str, str], None]) -> None:
        key = address.key.read_bytes()  # OSError: no console shares there
        self._conn = _open_connection(address, key)
        self._state = state
        self._on_reply = on_reply
        self._send_lock = threading.Lock()
        self._closed = threading.Event()
        state.connected()
        threading.Thread(target=self._receive, name="share client", daemon=True).start()

    def _receive(self) -> None:
        try:
            while True:
                message = self._conn.recv()
                kind = message[0]
                if kind == "view":
                    self._state.mirror(message[1], bool(message[2]))
                elif kind == "said":
                    self._reply("said", str(message[1]), str(message[2]))
                elif kind in ("granted", "refused"):
                    self._reply(kind, str(message[1]), "information")
        except Exception:  # noqa: BLE001 - closed, cut, or a copy that does not read
            pass
        if not self._closed.is_set():
            self._state.lost()
            self._reply("gone", "the controlling console closed", "warning")

    def _reply(self, kind: str, text: str, severity: str) -> None:
        with contextlib.suppress(Exception):  # a console quitting: nobody to tell
            self._on_reply(kind, text, severity)

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
    except (OSError, EOFError):
        return None
