"""The robot URLs the console opened, newest first: the connection
manager's "Recent" group (console/connect_screen.py).

Kept in ``$XDG_STATE_HOME/stairbot/recent-urls.json`` (``~/.local/state``
when unset), beside the run journals: ``{"urls": [URL, ...]}``, at most
:data:`MAX_RECENT`, rewritten whole through a temporary file and a rename,
so a console killed while writing leaves the old list or the new one, never
half of one.  A file that is not such a list (corrupt, too large, not a
regular file) is ignored with one line saying so, and replaced at the next
successful open.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from pathlib import Path

from stairbot.errors import InputError
from stairbot.files import read_bytes, shown

MAX_RECENT = 10
MAX_URL_CHARS = 2000
"""A longer URL is not remembered (nor one with a line break): the list is
shown one URL a row."""
MAX_FILE_BYTES = 64 * 1024


def recent_path() -> Path:
    state = os.environ.get("XDG_STATE_HOME") or str(Path.home() / ".local" / "state")
    return Path(state) / "stairbot" / "recent-urls.json"


def load(path: Path | None = None) -> tuple[list[str], str | None]:
    """The remembered URLs, newest first, and None; or no URLs and one line
    saying why the file was ignored.  No file yet: no URLs, None."""
    path = path or recent_path()
    if not path.exists():
        return [], None
    try:
        data = read_bytes(path, InputError, what="the recent URLs", limit=MAX_FILE_BYTES,
                          timeout_s=2.0)
    except InputError as exc:
        return [], f"recent URLs ignored: {exc}"
    try:
        raw = json.loads(data)
        urls = raw["urls"]
        if not isinstance(urls, list) or not all(_fits(u) for u in urls):
            raise ValueError
    except (ValueError, KeyError, TypeError, UnicodeDecodeError):
        return [], (f"recent URLs ignored: {shown(path)} is not a list of URLs "
                    "(replaced at the next open)")
    return list(dict.fromkeys(urls))[:MAX_RECENT], None


def _fits(url: object) -> bool:
    return isinstance(url, str) and 0 < len(url) <= MAX_URL_CHARS and url.isprintable()


def remember(url: str, path: Path | None = None) -> str | None:
    """Put ``url`` first in the list (once), keep the newest
    :data:`MAX_RECENT`; None, or one line saying why it could not be
    written.  A corrupt list is replaced by one holding ``url``."""
    if not _fits(url):
        return None
    path = path or recent_path()
    urls, _ = load(path)
    urls = [url, *(u for u in urls if u != url)][:MAX_RECENT]
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".recent-urls.", suffix=".tmp")
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as out:
                json.dump({"urls": urls}, out, indent=1)
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
    except OSError as exc:
        return f"{url} not remembered: {shown(path)}: {exc.strerror or exc}"
    return None
