"""Every file the command line reads or appends to, read and written one way.

Reading (:func:`read_input`): a scenario, a robot config, a sweep spec, a run
journal.  The file is looked at with ``os.stat`` before it is opened, so a FIFO
(which would block until a writer comes), a device (``/dev/zero`` never ends)
or a directory is refused, not read; only a regular file is, and only up to a
size cap (:data:`MAX_TOML_BYTES` for the TOML inputs); the whole read runs in
a helper thread the caller waits for at most :data:`READ_TIMEOUT_S` (a hung
network mount).  Every refusal is one :class:`~stairbot.errors.InputError`
naming the file and what is allowed.

Writing (:class:`LineFile`): the event record and the journal append whole
lines with ``os.write`` (no buffer left behind to fail again at close).  A
write the disk refuses raises :class:`OutputError`: the run stops, the robot
is stopped, and what was written before stays.

Pure Python, standard library only: part of the core.
"""

from __future__ import annotations

import errno
import os
import stat
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from stairbot.errors import InputError, OutputError

MAX_TOML_BYTES = 1 << 20
"""A scenario, config or sweep spec is at most 1 MiB (the shipped ones are
under 10 kB)."""

READ_TIMEOUT_S = 10.0
"""How long a read may take before the file is given up on."""

MAX_SHOWN = 300
"""A path longer than this is shortened in messages (its end kept)."""

_write = os.write  # the one write call (tests swap it to fill the disk)


def shown(path: str | os.PathLike[str]) -> str:
    """A path as a message names it: whole, or its last :data:`MAX_SHOWN`
    characters after an ellipsis and its length."""
    text = str(path)
    if len(text) <= MAX_SHOWN:
        return text
    return f"...{text[-MAX_SHOWN:]} (a path of {len(text)} characters)"


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a regular file"


def _read(path: Path, limit: int, what: str) -> bytes | str:
    """The file's bytes, or the problem (a str) to report."""
    try:
        st = os.stat(path)
        if not stat.S_ISREG(st.st_mode):
            return f"cannot read: {_kind(st.st_mode)}; allowed: a regular file"
        if st.st_size > limit:
            return (f"cannot read: {st.st_size} bytes, too large for {what}; allowed: a "
                    f"regular file of at most {limit} bytes")
        # O_NONBLOCK: a FIFO put in its place since the stat does not block the open
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                return "cannot read: not a regular file; allowed: a regular file"
            with os.fdopen(fd, "rb", closefd=False) as f:
                data = f.read(limit + 1)
        finally:
            os.close(fd)
    except OSError as exc:
        return f"cannot read: {exc.strerror or exc}"
    if len(data) > limit:
        return f"cannot read: grew past {limit} bytes while read; allowed: at most {limit} bytes"
    return data


def read_bytes(path: str | os.PathLike[str], error: type[InputError], *, what: str,
               limit: int = MAX_TOML_BYTES, timeout_s: float = READ_TIMEOUT_S) -> bytes:
    """The bytes of the regular file ``path`` (at most ``limit`` of them).
    Raises ``error`` (one line naming the file, ``what`` it should be and what
    is allowed) for anything else: missing, a FIFO, a device, a directory,
    too large, unreadable, or not read within ``timeout_s``."""
    p = Path(path)
    out: list[bytes | str] = []
    reader = threading.Thread(target=lambda: out.append(_read(p, limit, what)),
                              name=f"read {shown(p)}", daemon=True)
    reader.start()
    reader.join(timeout_s)
    if not out:
        raise error(shown(p), None, f"cannot read: not read within {timeout_s:g} s; allowed: "
                    "a regular file that can be read")
    result = out[0]
    if isinstance(result, str):
        raise error(shown(p), None, result)
    return result


def read_input(path: str | os.PathLike[str], error: type[InputError], *, what: str,
               limit: int = MAX_TOML_BYTES) -> str:
    """:func:`read_bytes` as UTF-8 text.  Raises ``error`` when it is not."""
    data = read_bytes(path, error, what=what, limit=limit)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise error(shown(path), None, "not a UTF-8 text file") from None


def is_file(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` names something that exists (a name too long for the
    system, or otherwise unusable, does not)."""
    try:
        os.stat(path)
    except (OSError, ValueError):
        return False
    return True


def open_regular(path: str | os.PathLike[str], error: type[InputError], what: str) -> int:
    """A read-only descriptor of the regular file ``path`` (any size: the
    caller reads what it needs).  Raises ``error`` naming the file for
    anything else (stat first: a FIFO or a device is never opened)."""
    try:
        st = os.stat(path)
        if not stat.S_ISREG(st.st_mode):
            raise error(shown(path), None, f"cannot read {what}: {_kind(st.st_mode)}; "
                        f"allowed: {what} that is a regular file")
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except (OSError, ValueError) as exc:
        msg = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise error(shown(path), None, f"cannot read {what}: {msg}") from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise error(shown(path), None, f"cannot read {what}: not a regular file; "
                    f"allowed: {what} that is a regular file")
    return fd


def refused(path: str | os.PathLike[str], what: str, exc: OSError) -> OutputError:
    """The OutputError of a write (or fsync) the disk refused: ``PATH: cannot
    write WHAT: REASON``."""
    return OutputError(shown(path), what, exc.strerror or str(exc))


@contextmanager
def writing(path: str | os.PathLike[str], what: str) -> Iterator[None]:
    """An OSError from writing ``path`` in the block raised as :func:`refused`'s
    OutputError (a full disk)."""
    try:
        yield
    except OSError as exc:
        raise refused(path, what, exc) from None


class LineFile:
    """A file written one whole line at a time with ``os.write`` (``fresh``:
    truncated first, else appended; ``sync``: each line fsync'ed before
    :meth:`write` returns; ``regular``: only a regular file, or a new one).
    ``what`` names it in messages ("the record").  Raises InputError when it
    cannot be opened -- a FIFO no process reads is refused, not waited on --
    and OutputError when a write is refused (a full disk); after a refused
    write it takes no more lines (:attr:`failed` says why)."""

    def __init__(self, path: str | os.PathLike[str], what: str, *, fresh: bool = True,
                 sync: bool = False, regular: bool = False,
                 error: type[InputError] = InputError) -> None:
        self.path = Path(path)
        self.what = what
        self.sync = sync
        self.failed: OutputError | None = None
        self._fd = -1
        flags = os.O_WRONLY | os.O_CREAT | os.O_APPEND | os.O_NONBLOCK \
            | (os.O_TRUNC if fresh else 0)
        try:
            if regular:
                try:
                    mode = os.stat(self.path).st_mode
                except FileNotFoundError:
                    mode = stat.S_IFREG
                if not stat.S_ISREG(mode):
                    raise error(shown(self.path), None, f"cannot write {what}: "
                                f"{_kind(mode)}; allowed: a regular file (or a new one)")
            fd = os.open(self.path, flags, 0o644)
            # writes block as usual once open (a FIFO with a reader, a slow disk)
            os.set_blocking(fd, True)
            self._fd = fd
        except (OSError, ValueError) as exc:
            msg = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            if isinstance(exc, OSError) and exc.errno == errno.ENXIO:
                msg = "a FIFO (named pipe) that no process reads"
            raise error(shown(self.path), None, f"cannot write {what}: {msg}") from None

    def write(self, line: str | bytes) -> None:
        """Write ``line`` whole (and durably, with ``sync``).  OutputError
        when the disk refuses it; a file that refused one is silent after."""
        if self.failed is not None or self._fd < 0:
            return
        data = line.encode("utf-8") if isinstance(line, str) else line
        try:
            while data:
                data = data[_write(self._fd, data):]
            if self.sync:
                os.fsync(self._fd)
        except OSError as exc:
            self.failed = refused(self.path, self.what, exc)
            raise self.failed from None

    def fileno(self) -> int:
        return self._fd

    def close(self) -> None:
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1
