"""Reading a run journal back (:mod:`stairbot.run.journal` writes it), every line
checked before a resume trusts any of it.

:func:`read_journal` refuses the journal -- one :class:`JournalError`
naming the file, the line and the field -- unless

* every whole line is a JSON object (numbers finite: ``NaN`` and
  ``Infinity`` are refused) of a known kind, chained: ``seq`` its line's
  number, ``prev`` the :func:`line_hash` of the line before;
* the first line starts the run, in this :data:`FORMAT`, with a run id,
  its contexts of this
  :data:`~stairbot.control.algorithm.context.CONTEXT_VERSION` (a context of
  another shape would be misread);
  every other line is of that run; nothing follows an end but a resume,
  and only after an end that was resumable;
* each record has its kind's fields, of their types: times finite and
  within :data:`MAX_TIME_S`, phases and modes known, the command's motors
  known and their speeds finite, the boards' identities whole numbers, and
  a context that :meth:`Context.from_dict` restores (whose phase is the
  tick's);
* the journal reaches its mark: the line the mark says was the last made
  durable is there, with the mark's hash (a journal cut short after it was
  written, by a copy or a damaged disk, is not).

Only the last line may be cut short (a power loss): it is left out.  The
whole file is read, in pieces of :data:`CHUNK` bytes (memory stays
bounded), up to :data:`MAX_JOURNAL_BYTES`.  Pure Python, standard library
only: part of the core.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO

from stairbot.control.algorithm.context import CONTEXT_VERSION, Context
from stairbot.control.algorithm.phases import BY_VALUE, Mode
from stairbot.errors import InputError
from stairbot.files import open_regular, shown
from stairbot.hardware import MotorId

FORMAT = 2
"""The journal's format: chained records and a mark (format 1 had neither)."""
MAX_LINE = 1 << 20  # a journal line longer than this is not one of ours
MAX_JOURNAL_BYTES = 1 << 30  # an hour's run writes about 85 MB (472 bytes a tick)
MAX_MARK_BYTES = 4096
CHUNK = 1 << 20
MAX_TIME_S = 1e9
MAX_SPEED = 1e6  # turns/s
MAX_RUN_ID = 64
KINDS = ("start", "tick", "resume", "end")
MOTORS = frozenset(m.name for m in MotorId)
MODES = frozenset(m.value for m in Mode)


class JournalError(InputError):
    """A journal that cannot be written or read: names the file and why."""


def line_hash(line: bytes) -> str:
    """The hash a journal line is chained by (its bytes without the newline)."""
    return hashlib.sha256(line).hexdigest()[:32]


def mark_path(path: str | Path) -> Path:
    """Where the mark of the journal at ``path`` is kept: beside it."""
    p = Path(path)
    return p.with_name(p.name + ".synced")


@dataclass(frozen=True)
class Tail:
    """Where a journal's chain ends: its last whole line's ``seq`` and hash,
    and ``size``, the bytes up to the end of that line."""

    seq: int
    hash: str
    size: int


@dataclass
class JournalState:
    """What a journal says of its run: its start record, the last tick (the
    start when there is none) and the last context written, and its end
    (None: the run did not end, or was resumed after it).  ``boards``: the
    boards' identities in the last record that gives them; ``tail``: where
    its chain ends (a resumed run appends after it)."""

    path: str
    start: dict[str, Any]
    last: dict[str, Any]
    context: dict[str, Any] | None
    context_time_s: float | None
    end: dict[str, Any] | None
    resumes: int = 0
    boards: Any = field(default=None)
    tail: Tail | None = None


class _Bad(Exception):
    """A field of a record is wrong: (field, problem)."""

    def __init__(self, key: str | None, problem: str) -> None:
        super().__init__(problem)
        self.key, self.problem = key, problem


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a number a journal holds")


def _number(rec: dict[str, Any], key: str, limit: float = MAX_TIME_S) -> float:
    value = rec.get(key)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _Bad(key, f"{value!r} is not a number" if key in rec else "missing")
    if not math.isfinite(value) or abs(value) > limit:
        raise _Bad(key, f"{value!r} is out of range; allowed: finite, at most {limit:g} "
                   "in magnitude")
    return float(value)


def _text(rec: dict[str, Any], key: str) -> str:
    value = rec.get(key)
    if not isinstance(value, str):
        raise _Bad(key, f"{value!r} is not a string" if key in rec else "missing")
    return value


def _whole(value: object, key: str, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= 2**63:
        raise _Bad(key, f"{value!r} is not a whole number of at least {low}")
    return value


def _boards(rec: dict[str, Any]) -> None:
    if "boards" not in rec:
        raise _Bad("boards", "missing")
    boards = rec["boards"]
    if boards is None:
        return
    if not isinstance(boards, dict):
        raise _Bad("boards", "must be a table of each board's identity, or null")
    for name, ident in boards.items():
        key = f"boards.{name}"
        if not isinstance(ident, dict) or not {"serial", "uptime_ms"} <= set(ident) or (
                set(ident) - {"serial", "uptime_ms", "boot"}):
            raise _Bad(key, "must be a table of serial, uptime_ms and boot (where given)")
        _whole(ident["serial"], f"{key}.serial", 0)
        _whole(ident["uptime_ms"], f"{key}.uptime_ms", -1)
        if "boot" in ident:
            _whole(ident["boot"], f"{key}.boot", 0)


def _phase(rec: dict[str, Any], key: str = "phase") -> str:
    value = rec.get(key)
    if value not in BY_VALUE:
        raise _Bad(key, f"{value!r} is not a phase")
    return str(value)


def _check_start(rec: dict[str, Any]) -> None:
    if rec.get("format") != FORMAT:
        raise _Bad("format", f"written by another version of stairbot (journal format "
                   f"{rec.get('format', 1)!r}; this one reads {FORMAT}): it cannot be checked, "
                   "so it is not resumed")
    version = rec.get("context_version", 1)  # version 1 journals did not name it
    if version != CONTEXT_VERSION:
        raise _Bad("context_version", f"its contexts are of version {version!r}; this "
                   f"stairbot reads context version {CONTEXT_VERSION}: they would be misread, "
                   "so it is not resumed")
    run_id = _text(rec, "run_id")
    if not 0 < len(run_id) <= MAX_RUN_ID or not run_id.isascii() or not run_id.isalnum():
        raise _Bad("run_id", f"{run_id!r} is not a run id; allowed: 1 to {MAX_RUN_ID} "
                   "letters and digits")
    for key in ("url", "config", "config_sha256", "scenario"):
        _text(rec, key)
    if rec.get("mode") not in MODES:
        raise _Bad("mode", f"{rec.get('mode')!r} is not a mode; allowed: "
                   + ", ".join(sorted(MODES)))
    _boards(rec)
    _number(rec, "time_s")


def _check_tick(rec: dict[str, Any]) -> None:
    _whole(rec.get("n"), "n", 0)
    _number(rec, "time_s")
    phase = _phase(rec)
    if not isinstance(rec.get("estopped"), bool):
        raise _Bad("estopped", f"{rec.get('estopped')!r} is not true or false")
    command = rec.get("command")
    if not isinstance(command, dict):
        raise _Bad("command", "must be a table of the speeds sent")
    for motor in command:
        if motor not in MOTORS:
            raise _Bad(f"command.{motor}", "not a motor; allowed: " + ", ".join(sorted(MOTORS)))
        _number(command, motor, MAX_SPEED)
    _boards(rec)
    if "context" in rec:
        try:
            ctx = Context.from_dict(rec["context"], "context")
        except InputError as exc:
            raise _Bad(f"context.{exc.field}" if exc.field else "context", exc.problem) from None
        if ctx.phase != phase:
            raise _Bad("context.phase", f"{ctx.phase!r} differs from the tick's {phase!r}")


def _check_resume(rec: dict[str, Any]) -> None:
    _number(rec, "time_s")
    _boards(rec)


def _check_end(rec: dict[str, Any]) -> None:
    _text(rec, "outcome")
    if rec.get("error") is not None:
        _text(rec, "error")
    _number(rec, "time_s")
    if not isinstance(rec.get("resumable", False), bool):
        raise _Bad("resumable", f"{rec.get('resumable')!r} is not true or false")


_CHECKS = {"start": _check_start, "tick": _check_tick, "resume": _check_resume,
           "end": _check_end}


def _lines(f: BinaryIO, where: str) -> Iterator[tuple[bytes, int]]:
    """Each whole line of ``f`` (without its newline) and the offset just past
    it; a last line with no newline (cut short) is left out."""
    carry, offset = b"", 0
    while piece := f.read(CHUNK):
        parts = (carry + piece).split(b"\n")
        carry = parts.pop()
        for raw in parts:
            offset += len(raw) + 1
            yield raw, offset
        if len(carry) > MAX_LINE:
            raise JournalError(where, None, f"a line of more than {MAX_LINE} bytes: not a "
                               "journal")


def _read_mark(path: Path) -> tuple[dict[str, Any] | None, str]:
    """The journal's mark, or None and why it cannot be used."""
    mark = mark_path(path)
    try:
        fd = open_regular(mark, JournalError, "a journal's mark")
    except JournalError as exc:
        return None, (f"its mark {shown(mark)} cannot be read ({exc.problem}): whether the "
                      "journal is whole cannot be told")
    with os.fdopen(fd, "rb") as f:
        data = f.read(MAX_MARK_BYTES)
    try:
        mark_rec = json.loads(data.split(b"\n", 1)[0], parse_constant=_no_constant)
    except (ValueError, RecursionError):
        mark_rec = None
    if not (isinstance(mark_rec, dict) and isinstance(mark_rec.get("run_id"), str)
            and isinstance(mark_rec.get("hash"), str) and isinstance(mark_rec.get("seq"), int)
            and not isinstance(mark_rec.get("seq"), bool) and mark_rec["seq"] >= 0):
        return None, (f"its mark {shown(mark)} is damaged: whether the journal is whole "
                      "cannot be told")
    return mark_rec, ""


def read_journal(path: str | Path) -> JournalState:
    """The run of the journal at ``path``, every line checked (see the module
    docstring).  JournalError (one line naming the file, and the line and
    field when one is wrong) when it is missing, not a regular file, too
    large, holds no run, or fails a check."""
    p = Path(path)
    where = shown(p)
    fd = open_regular(p, JournalError, "a journal")
    mark, mark_problem = _read_mark(p)
    start: dict[str, Any] | None = None
    last: dict[str, Any] | None = None
    context: dict[str, Any] | None = None
    end: dict[str, Any] | None = None
    boards: Any = None
    resumes, seq, prev, size = 0, -1, "", 0
    marked: str | None = None  # the hash of the line the mark names, once read
    try:
        with os.fdopen(fd, "rb") as f:
            if os.fstat(f.fileno()).st_size > MAX_JOURNAL_BYTES:
                raise JournalError(where, None, f"more than {MAX_JOURNAL_BYTES} bytes: too "
                                   "large to check; allowed: a journal of at most that size")
            for raw, end_of_line in _lines(f, where):
                size = end_of_line
                seq += 1
                line = f"line {seq + 1}"
                if len(raw) > MAX_LINE:
                    raise JournalError(where, line, f"more than {MAX_LINE} bytes: not a "
                                       "journal's line")
                try:
                    rec = json.loads(raw)
                except (ValueError, RecursionError):
                    raise JournalError(where, line, "not a JSON object (damaged, or a line "
                                       "cut short before others were added)") from None
                if not isinstance(rec, dict) or rec.get("kind") not in KINDS:
                    raise JournalError(where, line, "not a record of a journal (its kind: "
                                       f"{rec.get('kind') if isinstance(rec, dict) else None!r})")
                kind = rec["kind"]
                if seq == 0 and kind != "start":
                    raise JournalError(where, line, f"a {kind} record before the run's start")
                try:
                    if kind == "start" and seq > 0:
                        raise _Bad("kind", "a second start: a journal holds one run")
                    _CHECKS[kind](rec)
                    if rec.get("seq") != seq or rec.get("prev") != prev:
                        raise _Bad("seq", f"the chain breaks here (seq {rec.get('seq')!r}, "
                                   f"expected {seq}; or prev is not the line before's hash): "
                                   "a line was lost, added or changed")
                    if start is not None and rec.get("run_id") != start["run_id"]:
                        raise _Bad("run_id", f"{rec.get('run_id')!r} is not the run's "
                                   f"{start['run_id']!r}")
                    if end is not None and (kind != "resume" or not end.get("resumable")):
                        raise _Bad("kind", f"a {kind} record after the run's end")
                except _Bad as bad:
                    field_name = f"{line}: {bad.key}" if bad.key else line
                    raise JournalError(where, field_name, bad.problem) from None
                prev = line_hash(raw)
                if mark is not None and seq == mark["seq"]:
                    marked = prev
                if kind == "start":
                    start = rec
                elif kind == "tick":
                    last = rec
                    if "context" in rec:
                        context = rec
                elif kind == "resume":
                    resumes += 1
                    end = None
                else:
                    end = rec
                if "boards" in rec:
                    boards = rec["boards"]
    except OSError as exc:
        raise JournalError(where, None, f"cannot read the journal: {exc.strerror or exc}"
                           ) from None
    if start is None:
        raise JournalError(where, None, "holds no run (no start record)")
    if mark is None:
        raise JournalError(where, None, mark_problem + "; it is not resumed")
    if mark["run_id"] != start["run_id"]:
        raise JournalError(where, None, f"its mark {shown(mark_path(p))} is of another run "
                           f"({mark['run_id'][:8]}, the journal's {start['run_id'][:8]})")
    if seq < mark["seq"]:
        raise JournalError(where, None, f"cut short: it ends at line {seq + 1}, but line "
                           f"{mark['seq'] + 1} had been made durable ({shown(mark_path(p))}); "
                           "a journal that lost lines is not resumed")
    if marked != mark["hash"]:
        raise JournalError(where, f"line {mark['seq'] + 1}", "not the line that was made "
                           f"durable ({shown(mark_path(p))} has another hash): the journal "
                           "was changed")
    return JournalState(
        path=str(p), start=start, last=last or start,
        context=context["context"] if context else None,
        context_time_s=float(context["time_s"]) if context else None,
        end=end, resumes=resumes, boards=boards, tail=Tail(seq, prev, size))
