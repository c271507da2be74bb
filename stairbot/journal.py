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

* ``{"kind": "start", "run_id", "url", "config", "config_sha256",
  "scenario", "mode", "boards", "time_s"}`` -- a run began
  (``boards``: each board's serial number and uptime, or null in the
  simulation);
* ``{"kind": "tick", "run_id", "n", "time_s", "phase", "estopped",
  "command", "boards", "context"?}`` -- after each tick's command:
  ``command`` the speeds sent (turns/s), ``context`` the controller's whole
  context (:meth:`Context.to_dict`), written when the phase changes and
  otherwise every ``CONTEXT_EVERY`` ticks (it is about 2 kB; the phases'
  motion targets in it are absolute counter values, so a context a few
  ticks old carries on as well);
* ``{"kind": "resume", "run_id", "time_s", "boards"}`` -- a resumed run
  carries on here;
* ``{"kind": "end", "run_id", "outcome", "error", "time_s"}`` -- the run
  ended (a run with an end has nothing to resume).

A line cut short by a power loss is the last one, and is ignored when read.
Pure Python, standard library only: part of the core.
"""

from __future__ import annotations

import hashlib
import json
import os
import threading
import uuid
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO

from stairbot.errors import InputError, OutputError
from stairbot.files import LineFile, open_regular, refused, shown

CONTEXT_EVERY = 25  # ticks: half a second at the 20 ms tick
MAX_LINE = 1 << 20  # a journal line longer than this is not one of ours
TAIL_BYTES = 1 << 20  # how much of a journal's end is read to resume from


class JournalError(InputError):
    """A journal that cannot be written or read: names the file and why."""


def digest(data: Any) -> str:
    """SHA-256 of ``data`` as canonical JSON (a config's values, whatever file
    or name they came from)."""
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


class JournalWriter:
    """Appends records to a journal, each written whole before it returns and
    made durable (fsync) before it returns or, a tick, by its fsync thread
    (see the module docstring).  ``fresh`` starts the file anew (a new run);
    otherwise records are added (a resumed run).  ``sync=False`` (no fsync at
    all) is for measuring what fsync costs."""

    def __init__(self, path: str | Path, *, fresh: bool, sync: bool = True) -> None:
        self.path = Path(path)
        self.sync = sync
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise JournalError(shown(self.path), None,
                               f"cannot write the journal: {exc.strerror or exc}") from None
        # fsync is this class's own (see the module docstring)
        self._file = LineFile(self.path, "the journal", fresh=fresh, regular=True,
                              error=JournalError)
        if sync:  # the file's name is durable too
            try:
                dir_fd = os.open(self.path.parent, os.O_RDONLY)
                try:
                    os.fsync(dir_fd)
                finally:
                    os.close(dir_fd)
            except OSError as exc:
                self._file.close()
                raise JournalError(shown(self.path), None,
                                   f"cannot write the journal: {exc.strerror or exc}") from None
        self.run_id = ""
        self._ticks = 0
        self._phase: str | None = None
        # lines written, lines known durable; the fsync thread's state
        self._written = self._synced = 0
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
        """One record, whole; durable (fsync'ed) before it returns, or with
        ``durable=False`` by the fsync thread as soon as it can.  OutputError
        (once) when the disk refuses it or refused an earlier fsync; after
        that the journal is silent."""
        if self._failed_now():
            return
        try:
            self._file.write(json.dumps(record, separators=(",", ":"), allow_nan=False) + "\n")
        except OutputError:
            self._told = True
            raise
        if self._syncer is None:
            return
        with self._cv:
            self._written += 1
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

    def _sync_loop(self) -> None:
        """fsync whatever has been written, back to back, until closed."""
        while True:
            with self._cv:
                self._cv.wait_for(lambda: self._synced < self._written or self._closing)
                if self._synced >= self._written:
                    return  # closing, and everything is durable
                target = self._written
            try:
                os.fsync(self._file.fileno())
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
        self.write({"kind": "start", "run_id": self.run_id, "url": url, "config": config,
                    "config_sha256": config_sha256, "scenario": scenario, "mode": mode,
                    "boards": boards, "time_s": time_s})

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
        """Every line durable (the fsync thread finishes), then the file closed."""
        if self._syncer is not None:
            with self._cv:
                self._closing = True
                self._cv.notify_all()
            self._syncer.join()
        self._file.close()


@dataclass
class JournalState:
    """What a journal says of its last run: its start record, the last tick
    and the last context written, and its end (None: the run did not end)."""

    path: str
    start: dict[str, Any]
    last: dict[str, Any]
    context: dict[str, Any] | None
    context_time_s: float | None
    end: dict[str, Any] | None
    resumes: int = 0
    boards: Any = field(default=None)


def _records(data: bytes) -> list[dict[str, Any]]:
    out = []
    for raw in data.split(b"\n"):
        if not raw.strip():
            continue
        try:
            rec = json.loads(raw)
        except (ValueError, RecursionError):
            continue  # a line cut short by a power loss (the last), or a torn head
        if isinstance(rec, dict) and isinstance(rec.get("kind"), str):
            out.append(rec)
    return out


def _count_resumes(f: BinaryIO, run_id: str) -> int:
    """The resume records of ``run_id`` in the whole journal ``f``, read in
    TAIL_BYTES pieces: each is one line as :meth:`JournalWriter.write` puts
    it, beginning ``{"kind":"resume","run_id":RUN_ID``."""
    mark = b'\n{"kind":"resume","run_id":' + json.dumps(run_id).encode()
    f.seek(0)
    count, carry = 0, b"\n"  # the file's first line begins at a line's start too
    while piece := f.read(TAIL_BYTES):
        block = carry + piece
        count += block.count(mark)
        carry = block[-(len(mark) - 1):]  # a mark split between two pieces
    return count


def read_journal(path: str | Path) -> JournalState:
    """The last run of the journal at ``path``.  JournalError (one line
    naming the file) when it is missing, not a regular file, or holds no run.
    A journal may be any size: only its last ``TAIL_BYTES`` (1 MiB) are read,
    and its first ``MAX_LINE`` bytes when no run starts in them; and in a
    larger one, the resume records of its last run are counted through the
    whole file (byte search, no JSON)."""
    p = Path(path)
    fd = open_regular(p, JournalError, "a journal")
    try:
        with os.fdopen(fd, "rb") as f:
            size = os.fstat(f.fileno()).st_size
            f.seek(max(0, size - TAIL_BYTES))
            tail = f.read(TAIL_BYTES)
            if size > TAIL_BYTES:
                tail = tail[tail.find(b"\n") + 1:]  # the first line there may be cut
            records = _records(tail)
            starts = [r for r in records if r["kind"] == "start"]
            resumes: int | None = None
            if not starts and size > TAIL_BYTES:  # a long run: find its start
                f.seek(0)
                head = f.read(MAX_LINE)
                starts = [r for r in _records(head) if r["kind"] == "start"]
            if starts and size > TAIL_BYTES:  # resumes further back than the tail
                resumes = _count_resumes(f, starts[-1]["run_id"])
    except OSError as exc:
        raise JournalError(shown(p), None, f"cannot read the journal: {exc.strerror or exc}"
                           ) from None
    if not starts:
        raise JournalError(str(p), None, "holds no run (no start record)")
    start = starts[-1]
    run = [r for r in records if r.get("run_id") == start["run_id"]]
    ticks = [r for r in run if r["kind"] == "tick"]
    with_context = [r for r in ticks if isinstance(r.get("context"), dict)]
    ends = [r for r in run if r["kind"] == "end"]
    last = ticks[-1] if ticks else start
    ctx = with_context[-1] if with_context else None
    return JournalState(
        path=str(p), start=start, last=last,
        context=ctx["context"] if ctx else None,
        context_time_s=ctx["time_s"] if ctx else None,
        end=ends[-1] if ends else None,
        resumes=resumes if resumes is not None else
        sum(1 for r in run if r["kind"] == "resume"),
        boards=last.get("boards"))
