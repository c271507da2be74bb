"""The journal's fsync: a tick is written at once and made durable by the
journal's own thread (the control loop never waits on the disk); start and
end wait until they are durable; an fsync the disk refuses stops the run at
the next record, once."""

from __future__ import annotations

import errno
import json
import os
import threading
from pathlib import Path

import pytest

from stairbot.errors import OutputError
from stairbot.run import journal as journal_mod
from stairbot.run.journal import JournalWriter


class GatedFsync:
    """os.fsync that waits until the test opens the gate."""

    def __init__(self) -> None:
        self.gate = threading.Event()
        self.calls = 0
        self.real = os.fsync

    def __call__(self, fd: int) -> None:
        self.calls += 1
        self.gate.wait(10)  # bounded: a journal that waits for it fails, not hangs
        self.real(fd)


def tick(j: JournalWriter, n: int) -> None:
    j.tick(time_s=n * 0.02, phase="ascent_lift_first", estopped=False,
           command={"MTF": 10.0}, boards=None, context=lambda: {"phase": "x"})


def test_a_tick_does_not_wait_for_its_fsync_but_end_does(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "j.jsonl"
    j = JournalWriter(path, fresh=True)
    j.start(url="x://", config="c", config_sha256="0", scenario="s", mode="full",
            boards=None, time_s=0.0)
    fsync = GatedFsync()
    monkeypatch.setattr(journal_mod.os, "fsync", fsync)
    for n in range(5):  # the disk is stuck: the ticks still go on, written
        tick(j, n)
    lines = path.read_text().splitlines()
    assert [json.loads(x)["kind"] for x in lines] == ["start"] + ["tick"] * 5  # kill -9 safe
    ender = threading.Thread(target=j.end, args=("completed", None, 0.1))
    ender.start()
    ender.join(0.2)
    assert ender.is_alive()  # the end waits until it is durable
    fsync.gate.set()
    ender.join(10)
    assert not ender.is_alive()
    j.close()
    assert fsync.calls >= 1
    assert json.loads(path.read_text().splitlines()[-1])["kind"] == "end"


def test_an_fsync_the_disk_refuses_stops_the_run_at_the_next_record_once(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "j.jsonl"
    j = JournalWriter(path, fresh=True)
    j.start(url="x://", config="c", config_sha256="0", scenario="s", mode="full",
            boards=None, time_s=0.0)

    def refused(fd: int) -> None:
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    monkeypatch.setattr(journal_mod.os, "fsync", refused)
    tick(j, 0)  # written; its fsync fails in the journal's thread
    with pytest.raises(OutputError, match="cannot write the journal: Input/output error"):
        j.end("completed", None, 0.02)  # waits for durability: the failure is told
    assert j.failed is not None
    tick(j, 1)  # told once; silent after
    j.close()
    kinds = [json.loads(x)["kind"] for x in path.read_text().splitlines()]
    # the end was written before its fsync failed (or after the tick's had
    # failed: then not); nothing after the failure was told
    assert kinds in (["start", "tick"], ["start", "tick", "end"])
