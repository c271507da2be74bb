"""The run journal: where a run stands, on disk, after every tick, so that a
host that crashes, is killed or loses power leaves behind what the next one
needs to carry on (``stairbot run --resume``).

A journal is a JSON-lines file, one object a line, each written whole with
one ``write`` before the tick goes on -- so a host killed at any moment
(``kill -9``, a crash) leaves every tick it finished on the disk.  Against a
power loss each line is made durable with ``fsync`` too: ``start``,
``resume`` and ``end`` before the call returns; a ``tick`` by the journal's
own thread, at once and back to back with the next, so that the control loop
never waits on the disk (a slow or busy disk -- an SD card, another
program's writes -- took 0.2 ms a tick at the median and up to 4 ms here,
longer than a tick of a simulation at x20).  A power loss may then cost the
ticks since the last fsync finished: the one in flight, rarely more.

Every record carries ``seq`` (its line's number, from 0) and ``prev`` (the
:func:`line_hash` of the line before; "" on the first): a line lost, added
or changed in the middle breaks the chain.  Beside the journal, its mark
(:func:`mark_path`, ``JOURNAL.synced``) says which line was the last made
durable, and that line's hash; the fsync thread rewrites it (and fsyncs it)
after each fsync of the journal.  A journal whose lines end before its mark's
was cut short after it was written -- not by a killed host, which leaves
every line it wrote, nor by a power loss, which costs only lines after the
mark -- and is not resumed (:mod:`stairbot.run.journal_read` checks all this).

* ``{"kind": "start", "seq", "prev", "run_id", "format", "context_version",
  "url", "config", "config_sha256", "scenario", "mode", "boards", "time_s"}``
  -- a run began (``format``: :data:`FORMAT`; ``context_version``: the shape
  of its contexts, :data:`~stairbot.control.algorithm.context.CONTEXT_VERSION`,
  absent before version 2; ``boards``: each board's identity --
  serial number, uptime, and boot id where the boards give one -- or null
  in the simulation);
* ``{"kind": "tick", "seq", "prev", "run_id", "n", "time_s", "phase",
  "estopped", "command", "boards", "context"?}`` -- after each tick's
  command: ``command`` the speeds sent (turns/s), ``context`` the
  controller's whole context (:meth:`Context.to_dict`), written when the
  phase changes and otherwise every ``CONTEXT_EVERY`` ticks (it is about
  2 kB; the phases' motion targets in it are absolute counter values, so a
  context a few ticks old carries on as well);
* ``{"kind": "resume", "seq", "prev", "run_id", "time_s", "boards"}`` -- a
  resumed run carries on here;
* ``{"kind": "end", "seq", "prev", "run_id", "outcome", "error", "time_s",
  "resumable"?}`` -- the run ended (a run with an end that is not
  resumable has nothing to resume).

A file holds one run: a new run starts it anew, a resumed one appends.  A
line cut short by a power loss can only be the last; a resume drops it
before it appends.  Pure Python, standard library only: part of the core.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import threading
import uuid
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from stairbot.control.algorithm.context import CONTEXT_VERSION
from stairbot.errors import OutputError
from stairbot.files import LineFile, refused, shown
from stairbot.run.journal_read import (
    FORMAT,
    MAX_LINE,
    JournalError,
    JournalState,
    Tail,
    line_hash,
    mark_path,
    read_journal,
)

CONTEXT_EVERY = 25  # ticks: half a second at the 20 ms tick
MARK_BYTES = 256  # the mark's one line, padded: each rewrite covers the last


def digest(data: Any) -> str:
    """SHA-256 of ``data`` as canonical JSON (a config's values, whatever file
    or name they came from)."""
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


class JournalWriter:
    """Appends records to a journal, each written whole before it returns and
    made durable (fsync) before it returns or, a tick, by its fsync thread
    (see the module docstring), the mark rewritten after each fsync.
    ``fresh`` starts the file anew (a new run); otherwise records are added
    after ``tail`` (a resumed run; whatever follows it -- a line cut short --
    is dropped first).  ``sync=False`` (no fsync at all, the mark written on
    close) is for measuring what fsync costs."""

    def __init__(self, path: str | Path, *, fresh: bool, sync: bool = True,
                 tail: Tail | None = None) -> None:
        self.path = Path(path)
        self.sync = sync
        if not fresh and tail is None:
            raise ValueError("appending to a journal takes the tail its chain ends at")

        def cannot(exc: OSError) -> JournalError:
            return JournalError(shown(self.path), None,
                                f"cannot write the journal: {exc.strerror or exc}")
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise cannot(exc) from None
        # fsync is this class's own (see the module docstring)
        self._file = LineFile(self.path, "the journal", fresh=fresh, regular=True,
                              error=JournalError)
        try:
            if tail is not None and os.fstat(self._file.fileno()).st_size > tail.size:
                os.truncate(self.path, tail.size)  # a line cut short by a power loss
            self._mark = os.open(mark_path(self.path), os.O_WRONLY | os.O_CREAT
                                 | (os.O_TRUNC if fresh else 0), 0o644)
        except OSError as exc:
            self._file.close()
            raise cannot(exc) from None
        if sync:  # the files' names are durable too
            try:
                dir_fd = os.open(self.path.parent, os.O_RDONLY)
                try:
                    os.fsync(dir_fd)
                finally:
                    os.close(dir_fd)
            except OSError as exc:
                self._close_files()
                raise cannot(exc) from None
        self.run_id = ""
        self._ticks = 0
        self._phase: str | None = None
        # the chain: the next line's seq, the last line's hash
        self._seq, self._prev = (0, "") if tail is None else (tail.seq + 1, tail.hash)
        # lines written, lines known durable, the last line written (seq, hash)
        # and the last known durable; the fsync thread's state
        self._written = self._synced = 0
        self._last: tuple[int, str] | None = None
        self._marked: tuple[int, str] | None = None
        self.syncs = 0  # fsyncs done (one covers every line written before it)
        self._closing = False
        self._told = False  # the caller has had the OutputError
        self._cv = threading.Condition()
        self._syncer: threading.Thread | None = None
        if sync:
            self._syncer = threading.Thread(target=self._sync_loop, name="journal fsync",
                                            daemon=True)
            self._syncer.start()

    @property
    def failed(self) -> OutputError | None:
        """Why the disk refused a record (the journal takes no more then)."""
        return self._file.failed

    def write(self, record: Mapping[str, Any], durable: bool = True) -> None:
        """One record, whole, chained (``seq`` and ``prev`` put after its
        ``kind``); durable (fsync'ed, the mark rewritten) before it returns,
        or with ``durable=False`` by the fsync thread as soon as it can.
        OutputError (once) when the disk refuses it or refused an earlier
        fsync; after that the journal is silent."""
        if self._failed_now():
            return
        chained = {"kind": record["kind"], "seq": self._seq, "prev": self._prev,
                   **{k: v for k, v in record.items() if k != "kind"}}
        line = json.dumps(chained, separators=(",", ":"), allow_nan=False).encode("utf-8")
        try:
            self._file.write(line + b"\n")
        except OutputError:
            self._told = True
            raise
        last = (self._seq, line_hash(line))
        self._seq, self._prev = self._seq + 1, last[1]
        if self._syncer is None:
            self._last = last
            return
        with self._cv:
            self._written += 1
            self._last = last
            self._cv.notify_all()
            if durable:
                self._cv.wait_for(lambda: self._synced >= self._written
                                  or self._file.failed is not None)
        self._failed_now()

    def _failed_now(self) -> bool:
        """Whether the journal failed; raises its OutputError the first time."""
        error = self._file.failed
        if error is None:
            return False
        if not self._told:
            self._told = True
            raise error
        return True

    def _write_mark(self, last: tuple[int, str]) -> None:
        """The mark: ``last`` (seq, hash) is the journal's last durable line."""
        text = json.dumps({"run_id": self.run_id, "seq": last[0], "hash": last[1]},
                          separators=(",", ":"))
        data = text.ljust(MARK_BYTES - 1).encode("utf-8") + b"\n"
        os.pwrite(self._mark, data, 0)
        self._marked = last

    def _sync_loop(self) -> None:
        """fsync whatever has been written, then the mark, back to back,
        until closed."""
        while True:
            with self._cv:
                self._cv.wait_for(lambda: self._synced < self._written or self._closing)
                if self._synced >= self._written:
                    return  # closing, and everything is durable
                target, last = self._written, self._last
            try:
                os.fsync(self._file.fileno())
                if last is not None:
                    self._write_mark(last)
                    os.fsync(self._mark)
            except OSError as exc:
                with self._cv:
                    self._file.failed = refused(self.path, "the journal", exc)
                    self._cv.notify_all()
                return
            with self._cv:
                self._synced = target
                self.syncs += 1
                self._cv.notify_all()

    def start(self, *, url: str, config: str, config_sha256: str, scenario: str, mode: str,
              boards: Any, time_s: float, run_id: str | None = None) -> None:
        self.run_id = run_id or uuid.uuid4().hex
        self.write({"kind": "start", "run_id": self.run_id, "format": FORMAT,
                    "context_version": CONTEXT_VERSION, "url": url,
                    "config": config, "config_sha256": config_sha256, "scenario": scenario,
                    "mode": mode, "boards": boards, "time_s": time_s})

    def resume(self, run_id: str, boards: Any, time_s: float) -> None:
        self.run_id = run_id
        self._phase = None
        self.write({"kind": "resume", "run_id": run_id, "time_s": time_s, "boards": boards})

    def tick(self, *, time_s: float, phase: str, estopped: bool,
             command: Mapping[str, float], boards: Any,
             context: Callable[[], dict[str, Any]]) -> None:
        """A tick's record (``context`` is called only when it is written)."""
        record: dict[str, Any] = {
            "kind": "tick", "run_id": self.run_id, "n": self._ticks, "time_s": time_s,
            "phase": phase, "estopped": estopped, "command": dict(command), "boards": boards}
        if phase != self._phase or self._ticks % CONTEXT_EVERY == 0:
            record["context"] = context()
        self._phase = phase
        self._ticks += 1
        self.write(record, durable=False)

    def end(self, outcome: str, error: str | None, time_s: float,
            resumable: bool = False) -> None:
        """The run's end.  ``resumable``: it ended on a lost link, the robot
        part way through its program, so ``--resume`` may carry it on."""
        record = {"kind": "end", "run_id": self.run_id, "outcome": outcome,
                  "error": error, "time_s": time_s}
        if resumable:
            record["resumable"] = True
        self.write(record)

    def close(self) -> None:
        """Every line durable (the fsync thread finishes), the mark saying
        so, then the files closed."""
        if self._syncer is not None:
            with self._cv:
                self._closing = True
                self._cv.notify_all()
            self._syncer.join()
        elif self._last is not None and self._file.failed is None:
            with contextlib.suppress(OSError):  # without fsync nothing was promised
                self._write_mark(self._last)
        self._close_files()

    def _close_files(self) -> None:
        self._file.close()
        if self._mark >= 0:
            os.close(self._mark)
            self._mark = -1

__all__ = ["CONTEXT_EVERY", "FORMAT", "MAX_LINE", "JournalError", "JournalState",
           "JournalWriter", "Tail", "digest", "line_hash", "mark_path", "read_journal"]
