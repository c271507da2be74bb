"""Fake boards in lockstep in a process of their own, on a pseudo-terminal
(`stairbot fake-boards --serial --lockstep`): their world stands still while
no host steps it, so a test on them is as fast as the machine and cannot
flake on timing.  A module of its own, not conftest.py."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


def stairbot(*args: str, env: dict[str, str] | None = None,
             cwd: Path | None = None) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "stairbot", *args], text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            stdin=subprocess.DEVNULL, env=env or dict(os.environ), cwd=cwd)


@contextmanager
def fake_boards(cwd: Path) -> Iterator[str]:
    """Serve fake boards in lockstep until the block ends; yields their URL."""
    proc = stairbot("fake-boards", "--serial", "--lockstep", cwd=cwd)
    assert proc.stdout is not None
    url = proc.stdout.readline().strip()
    try:
        assert url.startswith("serial:///dev/") and url.endswith("?lockstep=1"), url
        yield url
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
