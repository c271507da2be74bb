"""console/sharing.py without a robot: a hub serving a live state, and the
consoles that watch it.  Red-team findings on the first version: a watcher
that stops reading, or a connection that never proves the key, held up the
hub (and the controlling console's screen with it)."""

from __future__ import annotations

import os
import socket
import threading
import time
from pathlib import Path

import pytest

from stairbot.console.mirror import MirrorState
from stairbot.console.sharing import (
    Request,
    ShareAddress,
    ShareClient,
    ShareHub,
    _open_connection,
)
from stairbot.console.state import LiveState


@pytest.fixture
def address(tmp_path: Path) -> ShareAddress:
    return ShareAddress(str(tmp_path / "s.sock"), tmp_path / "s.key")


def wait(cond, what: str, bound_s: float = 30.0) -> None:  # type: ignore[no-untyped-def]
    """The bound only stops a broken test."""
    for _ in range(int(bound_s / 0.02)):
        if cond():
            return
        time.sleep(0.02)
    raise AssertionError(f"never happened: {what}")


def test_a_watcher_that_asks_then_stops_reading_blocks_neither_the_answer_nor_the_others(
        address: ShareAddress) -> None:
    """Finding: the answer was sent on the controlling console's UI thread; an
    asker that stopped reading froze that console, its e-stop key with it."""
    state = LiveState(url="serial:///dev/x")
    asked: list[Request] = []
    stops: list[str] = []
    hub = ShareHub(address, state, on_estop=lambda who: stops.append(who) or "latched",
                   on_ask=asked.append)
    busy = threading.Event()

    def chatter() -> None:  # big copies, so a reader that stops has its socket full
        while not busy.is_set():
            state.note("x" * 50_000)
            time.sleep(0.05)

    try:
        stalled = _open_connection(address, address.key.read_bytes())
        stalled.send(("ask", "a console that stops reading"))
        wait(lambda: bool(asked), "the request passed on")
        threading.Thread(target=chatter, daemon=True).start()
        mirror = MirrorState()
        replies: list[str] = []
        client = ShareClient(address, mirror, lambda kind, text, sev: replies.append(kind))
        time.sleep(1.0)  # the stalled one's socket full meanwhile
        done = threading.Event()
        threading.Thread(target=lambda: (asked[0].answer(False, "no"), done.set()),
                         daemon=True).start()
        assert done.wait(5.0), "answering blocked"
        got = mirror.version
        wait(lambda: mirror.version > got + 3, "copies keep coming to the reader")
        assert client.send("estop")
        wait(lambda: "said" in replies, "the stop told")
        assert stops and stops[0].startswith("the console with pid")
        client.close()
        stalled.close()
    finally:
        busy.set()
        hub.close()


@pytest.mark.parametrize("first", [b"", b"\xff\xff\xff\xff", b"garbage that is no proof"])
def test_a_connection_that_does_not_prove_the_key_stops_no_one_else(
        address: ShareAddress, first: bytes) -> None:
    hub = ShareHub(address, LiveState(), on_estop=lambda who: "", on_ask=lambda r: None)
    try:
        with socket.socket(socket.AF_UNIX) as rogue:
            rogue.connect(address.socket)
            if first:
                rogue.sendall(first)
            mirror = MirrorState()
            client = ShareClient(address, mirror, lambda *a: None)
            wait(lambda: mirror.version > 0, "a console with the key still watches")
            client.close()
        with pytest.raises(OSError):  # without the key: no copy, no request
            _open_connection(address, os.urandom(32))
    finally:
        hub.close()


def test_the_key_file_is_the_users_alone_and_a_closed_hub_leaves_nothing(
        address: ShareAddress) -> None:
    hub = ShareHub(address, LiveState(), on_estop=lambda who: "", on_ask=lambda r: None)
    assert address.key.stat().st_mode & 0o077 == 0
    hub.close()
    assert not address.key.exists() and not Path(address.socket).exists()
