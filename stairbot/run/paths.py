"""Names for files a run writes (the event record): never one that would
overwrite a recording already on disk.

Pure Python, standard library only: part of the core.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

MAX_TRIES = 10_000
"""``name-1`` to ``name-9999`` are tried before giving up."""


def unused_path(path: str) -> str:
    """``path`` if nothing is stored there yet, else the first of
    ``name-1.ext``, ``name-2.ext``, ... that is free (beside it, same
    extension): writing a record never overwrites one already on disk.

    Only an existing *regular* file is stepped past: a FIFO, a device
    (``/dev/null``, ``/dev/full``, a terminal) or anything else that is not a
    regular file keeps its name, since writing to it destroys nothing stored
    (a directory keeps it too, and the writer then refuses it with its own
    message).  Raises FileExistsError when every name up to
    ``name-9999.ext`` is taken."""
    try:
        mode = os.stat(path).st_mode
    except OSError:  # nothing there (or not reachable: the writer says why)
        return path
    if not stat.S_ISREG(mode):
        return path
    p = Path(path)
    # "events.jsonl" -> "events-1.jsonl"; "events.tar.gz" keeps ".gz" only:
    # the name stays recognisable, and the suffix a reader picks a format by stays.
    stem, suffix = p.stem, p.suffix
    for n in range(1, MAX_TRIES):
        candidate = p.with_name(f"{stem}-{n}{suffix}")
        if not os.path.lexists(candidate):
            return str(candidate)
    raise FileExistsError(f"{path}: {stem}-1{suffix} to {stem}-{MAX_TRIES - 1}{suffix} "
                          "exist too")
