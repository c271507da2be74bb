"""The hardware tests (tests/hardware, ``pytest -m hardware``) run against
the fake boards in real time, over a pty and over CAN: they pass there, so a
failure on real boards is the boards' or the wire's.  Without
STAIRBOT_HW_URL they are skipped (the normal suite)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("where", [["--serial"], ["--can", "udp_multicast/239.74.166.7"]],
                         ids=["serial", "can"])
def test_the_hardware_tests_pass_on_the_fake_boards(where: list[str], tmp_path: Path) -> None:
    boards = subprocess.Popen([sys.executable, "-m", "stairbot", "fake-boards", *where],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert boards.stdout is not None
        url = boards.stdout.readline().strip()
        env = {**os.environ, "STAIRBOT_HW_URL": url}
        proc = subprocess.run(
            [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist",
             "-m", "hardware", str(ROOT / "tests" / "hardware")],
            capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)
    finally:
        boards.terminate()
        boards.communicate(timeout=10)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-1000:]
    assert "7 passed" in proc.stdout and "skipped" not in proc.stdout, proc.stdout[-2000:]
