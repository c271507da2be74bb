"""`stairbot console` in a real terminal (tmux): the robot is drawn on the
stairs, the picture changes as it climbs, and q quits (asking first
mid-run).  Skipped without tmux."""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

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


SGR = re.compile(r"\x1b\[([0-9;]*)m")


def colours(line: str) -> set[str]:
    """The foreground colours an ``capture-pane -e`` line sets (its SGR codes
    38;5;N and 38;2;R;G;B, and the basic 30-37, 90-97)."""
    found = set()
    for m in SGR.finditer(line):
        codes = m.group(1).split(";")
        i = 0
        while i < len(codes):
            if codes[i] == "38" and i + 2 < len(codes) and codes[i + 1] == "5":
                found.add(f"38;5;{codes[i + 2]}")
                i += 3
            elif codes[i] == "38" and i + 4 < len(codes) and codes[i + 1] == "2":
                found.add(";".join(codes[i:i + 5]))
                i += 5
            else:
                if codes[i].isdigit() and (30 <= int(codes[i]) <= 37 or 90 <= int(codes[i]) <= 97):
                    found.add(codes[i])
                i += 1
    return found


def test_boards_killed_mid_run_at_80x24_the_strip_says_down_and_no_stale_value_is_coloured(
        tmp_path: Path) -> None:
    """Issue 35's check in a real terminal: fake boards on a pty (real time),
    a run started, the boards killed with SIGKILL; captured with escapes
    (``capture-pane -e``).  Then at 60x20 the console says it is too small."""
    # COLUMNS and LINES would override the terminal's size (Textual reads them)
    env = {**{k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES")},
           "XDG_RUNTIME_DIR": str(tmp_path / "run"), "XDG_STATE_HOME": str(tmp_path / "state")}
    boards = subprocess.Popen([sys.executable, "-m", "stairbot", "fake-boards", "--serial"],
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                              env=env, cwd=tmp_path)
    base = ["tmux", "-L", f"stairbot-down-{os.getpid()}"]
    try:
        assert boards.stdout is not None
        url = boards.stdout.readline().strip()
        assert url.startswith("serial://"), url
        cmd = f"{sys.executable} -m stairbot console --robot {shlex.quote(url)}"
        subprocess.run([*base, "new-session", "-d", "-s", "console", "-x", "80", "-y", "24",
                        cmd], check=True, env=env)

        def run(*args: str) -> str:
            return subprocess.run([*base, *args], capture_output=True, text=True).stdout

        wait_screen(run, lambda s: "READY" in s.splitlines()[0] if s else False, "ready")
        run("send-keys", "-t", "console", "s")
        wait_screen(run, lambda s: "type yes and Enter" in s, "the start asks first")
        run("send-keys", "-t", "console", "y", "e", "s", "Enter")
        wait_screen(run, lambda s: "RUNNING" in s.splitlines()[0] if s else False, "running")
        boards.kill()
        boards.wait()
        down = wait_screen(run, lambda s: "STALE" in s and "DOWN" in s.splitlines()[0]
                           if s else False, "the link down, the values stale")
        escaped = run("capture-pane", "-p", "-e", "-t", "console").splitlines()
        (strip,) = [line for line in down.splitlines()[:1]]
        assert "DOWN" in strip and "LIVE" not in strip
        rows = {name: next(line for line in escaped if name in line)
                for name in ("front R SFR", "front L SFL", "back R  SBR", "back L  SBL",
                             "front wheels MWF", "back wheels  MWB", "front lift   MTF",
                             "back lift    MTB")}
        for name, line in rows.items():
            plain = SGR.sub("", line)
            assert not set("▶◀▲▼") & set(plain), (name, plain)  # no arrow on a stale motor
            # the row in the colour it began in (dim grey): no status colour after the
            # name (ok green, DIFFER red, a motor's arrow)
            assert colours(line[line.index(name):]) <= {"39"}, (name, line)
        # a terminal of 60x20 (a console of its own: the boards are gone)
        subprocess.run([*base, "new-session", "-d", "-s", "small", "-x", "60", "-y", "20",
                        f"{sys.executable} -m stairbot console"], check=True, env=env)

        def small(*args: str) -> str:
            return run(*[a if a != "console" else "small" for a in args])
        notice = wait_screen(small, lambda s: "too small" in s, "the too-small notice")
        assert "The terminal is too small: 60x20; the console needs" in notice
        assert "space: EMERGENCY STOP" in notice
    finally:
        subprocess.run([*base, "kill-server"], capture_output=True)
        if boards.poll() is None:
            boards.kill()
            boards.wait()
