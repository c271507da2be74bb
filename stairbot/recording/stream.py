"""The byte stream an MCAP writer writes into: a record file
(:class:`stairbot.files.LineFile`: opened the same way, a write the disk
refuses raises OutputError once and the file is silent after) that only
ever appends.

The writer is told it cannot seek (Foxglove's ``disable_seeking``), so it
writes each record whole, in order, and never goes back to patch one: what
was flushed before the process dies stays readable, and a FIFO with a
reader works as well as a file.  It still asks where it is
(``seek(0, SEEK_CUR)``) and may "seek" to where it already is.
"""

from __future__ import annotations

import errno
import io
import os

from stairbot.errors import OutputError
from stairbot.files import LineFile


class AppendStream:
    """A write-only, append-only binary stream over ``path`` (truncated
    first).  Raises InputError when it cannot be opened."""

    def __init__(self, path: str | os.PathLike[str], what: str = "the record") -> None:
        self._file = LineFile(path, what)
        self.path = self._file.path
        self._position = 0

    @property
    def failed(self) -> OutputError | None:
        """Why the disk refused a write (None while every write went through)."""
        return self._file.failed

    def write(self, data: bytes | bytearray | memoryview) -> int:
        """Write ``data`` whole.  Raises OutputError when the disk refuses it
        (then every later write raises it again: the writer must stop)."""
        if self._file.failed is not None:
            raise self._file.failed
        self._file.write(bytes(data))
        self._position += len(data)
        return len(data)

    def seek(self, offset: int, whence: int = io.SEEK_SET) -> int:
        """Where the stream is; only a seek to there is allowed."""
        target = offset if whence == io.SEEK_SET else self._position + offset \
            if whence == io.SEEK_CUR else -1
        if target != self._position:
            raise OSError(errno.ESPIPE, "an append-only stream cannot seek")
        return self._position

    def tell(self) -> int:
        return self._position

    def flush(self) -> None:
        """Nothing is buffered here: every write went to the file at once."""

    def close(self) -> None:
        self._file.close()
