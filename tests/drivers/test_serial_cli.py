"""The command line with board URLs: a malformed URL, a port that cannot
open, or a fake-boards invocation with bad input, is one line and exit 2; a
URL that opens but on which no board answers is a hardware error, one line
naming the board and the URL, and exit 1."""

from __future__ import annotations

import subprocess
import sys
import tempfile

import pytest


def stairbot(*args: str) -> subprocess.CompletedProcess[str]:
    # cwd elsewhere: the installed package runs, not the source tree
    return subprocess.run([sys.executable, "-m", "stairbot", *args], capture_output=True,
                          text=True, timeout=60, cwd=tempfile.gettempdir())


@pytest.mark.parametrize("url, says", [
    ("serial:///dev/no-such-port", "cannot open port /dev/no-such-port"),
    ("serial:///dev/ttyS0?baud=fast", "baud: 'fast' is not an integer"),
    ("can://virtual/x?timeout=-1", "timeout"),
])
def test_run_with_an_unusable_serial_port_exits_2_with_one_line(url: str, says: str) -> None:
    proc = stairbot("run", "--robot", url)
    assert proc.returncode == 2
    assert says in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    assert "Traceback" not in proc.stderr


@pytest.mark.parametrize("url, wire", [
    ("serial://loop://?timeout=0.01&retries=0", "serial port"),
    ("can://virtual/nobody-here?timeout=0.01&retries=0", "CAN bus"),
])
def test_run_where_no_board_answers_exits_1_naming_the_board_and_the_url(
        url: str, wire: str) -> None:
    proc = stairbot("run", "--robot", url)
    assert proc.returncode == 1
    assert proc.stderr == (f"stairbot: error: {url}: no motor board answered on the {wire} "
                           "(1 try of 10 ms)\n")
    assert proc.stdout == ""


def test_fake_boards_bad_input_exits_2() -> None:
    proc = stairbot("fake-boards", "--serial", "--drop", "1.5")
    assert proc.returncode == 2 and "allowed: 0 to 1 (a probability)" in proc.stderr
    proc = stairbot("fake-boards", "--serial", "--scenario", "/no/such/scenario.toml")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
