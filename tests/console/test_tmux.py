"""`stairbot console` in a real terminal (tmux): the robot is drawn on the
stairs, the picture changes as it climbs, and q quits (asking first
mid-run).  Skipped without tmux."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from collections.abc import Callable, Iterator

import pytest

pytestmark = pytest.mark.skipif(shutil.which("tmux") is None, reason="tmux is not installed")

CAPTION = re.compile(r"steps (\d)\|(\d)\|(\d)\s+MTF\s+([+-]\d+) mm")


@pytest.fixture
def tmux() -> Iterator[Callable[..., str]]:
    socket = f"stairbot-test-{os.getpid()}"
    base = ["tmux", "-L", socket]
    cmd = f"{sys.executable} -m stairbot console --speed 10x"
    subprocess.run([*base, "new-session", "-d", "-s", "console", "-x", "120", "-y", "40", cmd],
                   check=True)

    def run(*args: str) -> str:
        """A tmux command's output ("" once the session has ended)."""
        out = subprocess.run([*base, *args], capture_output=True, text=True)
        return out.stdout

    try:
        yield run
    finally:
        subprocess.run([*base, "kill-server"], capture_output=True)


def wait_screen(tmux: Callable[..., str], cond: Callable[[str], bool], what: str) -> str:
    """Capture the pane until ``cond`` holds (the bound only stops a broken test)."""
    screen = ""
    for _ in range(600):
        screen = tmux("capture-pane", "-p", "-t", "console")
        if cond(screen):
            return screen
        time.sleep(0.1)
    raise AssertionError(f"never happened: {what}\n{screen}")


def test_console_in_a_real_terminal_draws_the_robot_climbing(
        tmux: Callable[..., str]) -> None:
    first = wait_screen(tmux, lambda s: "READY" in s and CAPTION.search(s) is not None,
                        "the robot drawn on the stairs")
    m = CAPTION.search(first)
    assert m is not None and m.group(1, 2, 3) == ("0", "0", "0")
    assert any("\u2800" < ch <= "\u28ff" for ch in first)  # braille dots: the picture
    tmux("send-keys", "-t", "console", "s")
    climbing = wait_screen(
        tmux, lambda s: (c := CAPTION.search(s)) is not None and c.group(1) == "1",
        "segment 1 over the first tread")
    assert "RUNNING" in climbing
    picture = [line[:60] for line in first.splitlines()[2:24]]
    assert [line[:60] for line in climbing.splitlines()[2:24]] != picture
    tmux("send-keys", "-t", "console", "q")  # mid-run: the robot stops first, then it asks
    wait_screen(tmux, lambda s: "E-STOP" in s and "Quit the console?" in s, "the question")
    tmux("send-keys", "-t", "console", "y")
    wait_screen(tmux, lambda s: s == "", "the console quits and its pane closes")
