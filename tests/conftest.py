"""Fixtures every test folder shares."""

from __future__ import annotations

import errno
import os
from collections.abc import Iterator
from pathlib import Path

import pytest

from stairbot import files


@pytest.fixture
def disk_fills(monkeypatch: pytest.MonkeyPatch) -> Iterator[dict[str, int]]:
    """The disk fills after ``left[NAME]`` more writes to a file named NAME
    (every write of stairbot's whole-line files goes through ``files._write``);
    ``del left[NAME]`` makes room again."""
    left: dict[str, int] = {}
    real = files._write

    def write(fd: int, data: bytes) -> int:
        name = Path(os.readlink(f"/proc/self/fd/{fd}")).name
        if name in left:
            if left[name] <= 0:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            left[name] -= 1
        return real(fd, data)

    monkeypatch.setattr(files, "_write", write)
    yield left


@pytest.fixture
def recording_read_fails(monkeypatch: pytest.MonkeyPatch) -> None:
    """Reading a recording fails as a failing disk does: EIO from the read
    (``stairbot plot`` and ``stairbot replay`` read a recording whole through
    ``recording.read.recording_bytes``, which opens it with ``os.fdopen``)."""

    class Failing:
        def __init__(self, fd: int, mode: str) -> None:
            os.close(fd)

        def __enter__(self) -> Failing:
            return self

        def __exit__(self, *exc: object) -> None:
            pass

        def read(self) -> bytes:
            raise OSError(errno.EIO, "Input/output error")

    monkeypatch.setattr(os, "fdopen", Failing)
