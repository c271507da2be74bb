"""`stairbot console --serve`: the console in a browser (textual-serve),
driven in Debian's headless Chromium; the [HOST:]PORT it takes, the command
each browser tab runs, and the pages it refuses to serve."""

from __future__ import annotations

import contextlib
import http.client
import json
import os
import re
import shlex
import subprocess
import sys
import time
from pathlib import Path

import pytest
from browser import (
    CHROMIUM,
    chromium_page,
    chromium_tabs,
    press,
    screen_text,
    served_console,
    wait_screen,
)
from lockstep_boards import fake_boards

from stairbot.cli import main as stairbot_main
from stairbot.console.cli import build_parser
from stairbot.console.serve import (
    EXTRA_HINT,
    allowed_hosts,
    host_allowed,
    parse_bind,
    same_origin,
    served_argv,
    shell_command,
)
from stairbot.errors import InputError

# Skipped on a machine without chromium, but not in CI (CI=true), where
# scripts/test installs it: there its absence fails the test.
needs_chromium = pytest.mark.skipif(
    CHROMIUM is None and not os.environ.get("CI"),
    reason="Debian's chromium is not installed (scripts/test installs it)")

CAPTION = re.compile(r"steps (\d)\|(\d)\|(\d)\s+MTF")
BRAILLE = re.compile("[\u2801-\u28ff]")
MOTOR = re.compile(r"\b(MWF|MWB|MWR|MWL|MTF|MTB)\s+\S+\s+([+-]\d+\.\d)\b")


def motor_speeds(screen: str) -> dict[str, float]:
    """The motors panel's speeds (turns/s), by motor."""
    return {m.group(1): float(m.group(2)) for m in MOTOR.finditer(screen)}


def first_row(screen: str) -> str:
    """The banner's strip: the state, the latch, LIVE/DOWN, the URL."""
    return screen.splitlines()[0] if screen else ""


def banner_rows(screen: str) -> str:
    """The banner's rows (the strip, and the message under it), as one line."""
    return " ".join(" ".join(screen.splitlines()[:5]).split())


@needs_chromium
def test_the_console_in_a_browser_draws_the_robot_climbing_and_the_estop_stops_it() -> None:
    with served_console("--speed", "10x") as (url, _), chromium_page(url) as page:
        # the motors panel is drawn from the first reading, which may come a
        # frame after the picture: wait for it too (a CI run read it empty)
        ready = wait_screen(page, lambda s: "READY" in first_row(s) and CAPTION.search(s)
                            is not None and len(motor_speeds(s)) == 6,
                            "the robot drawn on the stairs, ready, its motors read")
        assert "side view" in ready and BRAILLE.search(ready)  # the picture is there
        m = CAPTION.search(ready)
        assert m is not None and m.group(1, 2, 3) == ("0", "0", "0")
        assert set(motor_speeds(ready).values()) == {0.0}
        press(page, "s")
        wait_screen(page, lambda s: "RUNNING" in first_row(s)
                    and (c := CAPTION.search(s)) is not None and c.group(1) == "1"
                    and any(motor_speeds(s).values()),
                    "running, segment 1 over the first tread, motors turning")
        press(page, "Space")
        stopped = wait_screen(
            page, lambda s: re.search(r"E-STOP\s+\(operator\)", first_row(s)) is not None
            and len(speeds := motor_speeds(s)) == 6 and not any(speeds.values()),
            "the latched emergency stop in the banner, every motor stopped")
        assert "RUNNING" not in first_row(stopped)
        press(page, "s")  # latched: a new run is refused until c clears it
        refused = wait_screen(page, lambda s: "EMERGENCY STOP latched" in banner_rows(s),
                              "the start refused")
        assert "RUNNING" not in first_row(refused)


@needs_chromium
def test_the_served_console_gets_the_options_given(tmp_path: Path) -> None:
    with served_console("--scenario", "wall_at_top", "--speed", "max",
                        cwd=str(tmp_path)) as (url, _), chromium_page(url) as page:
        ready = wait_screen(page, lambda s: "READY" in first_row(s), "the console ready")
        assert "wall_at_top" in first_row(ready)
        assert re.search(r"speed max\b", ready), ready


def group_members(pgid: int) -> set[int]:
    """The live processes of a process group (the server and its consoles)."""
    found = set()
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            with contextlib.suppress(OSError):
                if os.getpgid(int(entry)) == pgid and not zombie(int(entry)):
                    found.add(int(entry))
    return found


def zombie(pid: int) -> bool:
    with open(f"/proc/{pid}/stat") as f:
        return f.read().rsplit(")", 1)[1].split()[0] == "Z"


@needs_chromium
def test_a_tab_closed_mid_run_stops_the_run_and_ends_its_console(tmp_path: Path) -> None:
    with served_console("--speed", "10x", "--record", "events.jsonl",
                        cwd=str(tmp_path)) as (url, server), chromium_page(url) as page:
        wait_screen(page, lambda s: "READY" in first_row(s), "the console ready")
        press(page, "s")
        wait_screen(page, lambda s: "RUNNING" in first_row(s), "the run going")
        assert len(group_members(server.pid)) > 1  # the server and the tab's console
        page.close()
        record = tmp_path / "events.jsonl"
        for _ in range(600):
            if group_members(server.pid) == {server.pid}:
                break
            time.sleep(0.1)
        else:
            raise AssertionError(f"the tab's console still runs: {group_members(server.pid)}")
        ends = [e for e in map(json.loads, record.read_text().splitlines())
                if e["kind"] == "end"]
        assert [e["data"]["reason"] for e in ends] == ["the console closed"]
        assert ends[0]["data"]["outcome"] == "stopped"
        # no quit dialog could ask first: the e-stop latched, as quitting mid-run does
        assert any(e["message"] == "emergency stop by the operator (the console closed "
                   "mid-run)" for e in map(json.loads, record.read_text().splitlines()))


@needs_chromium
def test_a_second_tab_watches_the_first_tabs_robot_console_defect_9(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Before, each tab's console opened the robot for itself: the second was
    refused (a serial port is locked) or commanded it too."""
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    with fake_boards(tmp_path) as robot, served_console(
            "--robot", robot, cwd=str(tmp_path)) as (url, _), chromium_tabs(url) as open_tab:
        first = open_tab()
        wait_screen(first, lambda s: "READY" in first_row(s), "the first tab controls")
        second = open_tab()
        watched = wait_screen(second, lambda s: "WATCHING" in first_row(s)
                              and "READY" in first_row(s), "the second tab watches")
        assert "h asks for control" in banner_rows(watched)
        press(second, "s")
        wait_screen(second, lambda s: "watching: another console controls this robot" in s,
                    "a start refused there")
        assert "RUNNING" not in first_row(screen_text(first))
        press(second, "Space")
        wait_screen(first, lambda s: re.search(r"E-STOP\s+\(operator\)", first_row(s))
                    is not None, "the first tab's console latched the stop")
        wait_screen(second, lambda s: "E-STOP" in first_row(s), "the latch shown in both")


def test_host_and_origin_are_checked_before_a_console_opens() -> None:
    with served_console() as (url, _):
        port = int(url.rstrip("/").rsplit(":", 1)[1])

        def status(path: str, headers: dict[str, str]) -> int:
            conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
            try:
                conn.request("GET", path, headers=headers)
                return conn.getresponse().status
            finally:
                conn.close()

        ws = {"Upgrade": "websocket", "Connection": "Upgrade", "Sec-WebSocket-Version": "13",
              "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ=="}
        here = f"127.0.0.1:{port}"
        assert status("/", {"Host": here}) == 200
        assert status("/", {"Host": f"localhost:{port}"}) == 200
        # a name a web page pointed at 127.0.0.1 (DNS rebinding): no page
        assert status("/", {"Host": f"attacker.example:{port}"}) == 403
        # another site's page opening the websocket: no console
        assert status("/ws", {"Host": here, "Origin": "http://attacker.example", **ws}) == 403
        assert status("/ws", {"Host": here, **ws}) == 403


@pytest.mark.parametrize(("text", "bind"), [
    ("8000", ("127.0.0.1", 8000)),
    ("127.0.0.1:8000", ("127.0.0.1", 8000)),
    ("0.0.0.0:1", ("0.0.0.0", 1)),
    ("localhost:65535", ("localhost", 65535)),
    ("[::1]:8000", ("::1", 8000)),
])
def test_serve_takes_port_or_host_and_port(text: str, bind: tuple[str, int]) -> None:
    assert parse_bind(text) == bind


@pytest.mark.parametrize(("text", "says"), [
    ("0", "PORT must be a number from 1 to 65535"),
    ("65536", "PORT must be a number from 1 to 65535"),
    ("http", "PORT must be a number"),
    ("127.0.0.1:", "PORT must be a number"),
    ("-1", "PORT must be a number"),
    (":8000", "HOST is empty"),
    ("::1:8000", "in brackets"),
    ("a b:8000", "not an address or a host name"),
    ("nohost.invalid:8000", "cannot resolve HOST"),
    ("192.0.2.1:8000", "not one of this machine's"),  # TEST-NET-1: nobody's address
])
def test_a_bad_serve_value_is_one_line_and_exit_2(
        text: str, says: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert stairbot_main(["console", "--serve", text]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--serve" in err and says in err, err
    assert "Traceback" not in err


def test_a_port_in_use_is_one_line_and_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    with served_console() as (url, _):
        port = url.rstrip("/").rsplit(":", 1)[1]
        assert stairbot_main(["console", "--serve", f"127.0.0.1:{port}"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the port is in use" in err, err


def test_without_the_extra_it_names_the_extra(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setitem(sys.modules, "textual_serve", None)  # import fails as if absent
    monkeypatch.setitem(sys.modules, "textual_serve.server", None)
    assert stairbot_main(["console", "--serve", "8000"]) == 2
    err = capsys.readouterr().err
    assert err == f"stairbot: error: --serve: {EXTRA_HINT}\n"
    assert "stairbot[serve]" in err


def test_bad_console_options_are_refused_before_serving(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert stairbot_main(["console", "--serve", "8000", "--scenario", "no_such_one"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


NASTY = ["it's", 'a "b"', "$(touch pwned)", "`id`", "a;b", "-x", "sp ace", "*", "\\", "ü"]


@pytest.mark.parametrize("value", NASTY)
def test_each_tab_runs_the_console_with_the_options_as_given(value: str) -> None:
    args = build_parser().parse_args([f"--robot={value}", f"--scenario={value}",
                                      f"--config={value}", f"--record={value}",
                                      "--speed=10x", "--serve=8000"])
    argv = served_argv(args)
    assert argv[:4] == [sys.executable, "-m", "stairbot", "console"]
    again = build_parser().parse_args(argv[4:])
    for name in ("robot", "scenario", "config", "record"):
        assert getattr(again, name) == value
    assert again.speed == "10x" and again.serve is None  # the tab's console serves nothing


@pytest.mark.parametrize("value", NASTY)
def test_the_shell_hands_the_command_its_words_unchanged(value: str, tmp_path: Path) -> None:
    echo = [sys.executable, "-c", "import json, sys; print(json.dumps(sys.argv[1:]))"]
    out = subprocess.run(["sh", "-c", shell_command([*echo, value, f"--robot={value}"])],
                         capture_output=True, text=True, check=True, cwd=tmp_path)
    assert json.loads(out.stdout) == [value, f"--robot={value}"]
    assert list(tmp_path.iterdir()) == []  # nothing ran that was not asked for
    assert shlex.split(shell_command([value])) == [value]


def test_only_this_machines_names_and_its_own_page() -> None:
    names = allowed_hosts()
    assert host_allowed("127.0.0.1:8000", names) and host_allowed("[::1]:8000", names)
    assert host_allowed("192.168.1.20:8000", names) and host_allowed("LOCALHOST:8000", names)
    assert not host_allowed("evil.example:8000", names) and not host_allowed("", names)
    assert same_origin("http://127.0.0.1:8000", "127.0.0.1:8000")
    assert not same_origin("http://127.0.0.1:8001", "127.0.0.1:8000")
    assert not same_origin("null", "127.0.0.1:8000") and not same_origin(None, "127.0.0.1:8000")


def test_help_says_where_it_listens() -> None:
    text = " ".join(build_parser().format_help().split())
    assert "--serve [HOST:]PORT" in text and "127.0.0.1 unless given" in text
    assert "0.0.0.0" in text


def test_input_error_names_serve() -> None:
    with pytest.raises(InputError, match="--serve"):
        parse_bind("x:y")

