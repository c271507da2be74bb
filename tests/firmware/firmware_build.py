"""Building the firmware's native programs for the tests (tests/firmware):
the C compiler named by $CC, else cc, gcc or clang from PATH; without one
the calling test skips, saying so."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from stairbot.fakes.firmware_boards import find_cc

FIRMWARE = Path(__file__).resolve().parents[2] / "firmware"
WARNINGS = ["-std=c11", "-Wall", "-Wextra", "-Wpedantic", "-Wconversion", "-Wshadow", "-Werror"]
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer"]
WHEEL_LIMIT, LIFT_LIMIT = 1000, 10000  # the native plant's limits, mturn/s (native/plant.h)


def build(exe: Path, dirs: tuple[str, ...], files: tuple[str, ...], flags: list[str]) -> Path:
    """``exe`` from every .c of firmware's ``dirs`` and the ``files`` (paths
    under firmware/), with the Makefile's warnings and ``flags``.  Skips
    without a C compiler, or when ``flags`` ask for sanitizers it cannot link."""
    cc = find_cc()
    if cc is None:
        pytest.skip("no C compiler on PATH (cc, gcc or clang, or $CC): scripts/test installs gcc")
    sources = [str(p) for d in dirs for p in sorted((FIRMWARE / d).glob("*.c"))]
    sources += [str(FIRMWARE / f) for f in files]
    includes = [f"-I{FIRMWARE / d}" for d in ("core", "board", "plant", "native", "test")]
    built = subprocess.run([cc, *WARNINGS, *flags, *includes, *sources, "-o", str(exe)],
                           capture_output=True, text=True, check=False)
    if built.returncode != 0 and "sanitize" in built.stderr and SANITIZE[0] in flags:
        pytest.skip(f"{cc} cannot build with {' '.join(SANITIZE)}: {built.stderr.strip()}")
    assert built.returncode == 0, built.stderr
    return exe
