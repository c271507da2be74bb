"""Issue 12 item 5, "its latch leaks" (two hosts): a serial port is held by
one stairbot at a time; a second console, or `stairbot run`, on the same
port gets one clear line naming who holds it.  Before, both opened it."""

from __future__ import annotations

import asyncio
from collections.abc import Iterator
from pathlib import Path

import pytest
from lockstep_boards import fake_boards, stairbot
from pilot import banner, said, until

from stairbot.console.app import build_app
from stairbot.control.robot_config import load_config
from stairbot.run.robots import RobotSession, open_robot


@pytest.fixture
def boards_url(tmp_path: Path) -> Iterator[str]:
    with fake_boards(tmp_path) as url:
        yield url


@pytest.fixture
def held(boards_url: str, monkeypatch: pytest.MonkeyPatch,
         tmp_path: Path) -> Iterator[tuple[str, RobotSession]]:
    """The boards opened by this process, as a first console would."""
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))
    session = open_robot(boards_url, load_config())
    try:
        yield boards_url, session
    finally:
        session.close()


def test_a_second_console_on_the_same_port_is_refused_in_one_line(
        held: tuple[str, RobotSession]) -> None:
    url, _ = held
    port = url.removeprefix("serial://").split("?")[0]

    async def go() -> None:
        app = build_app(url=url)
        async with app.run_test(size=(80, 24)) as pilot:
            await app.workers.wait_for_complete()
            await until(pilot, lambda: "FAULT" in banner(app), "the refusal")
            line = f"serial port {port} is in use by another stairbot (pid "
            assert line in banner(app) and line in said(app)
            assert "\n" not in app.state.view().status.message
            assert app.engine.session is None
    asyncio.run(go())


def test_stairbot_run_on_a_port_a_console_holds_is_refused_in_one_line(
        held: tuple[str, RobotSession], tmp_path: Path) -> None:
    url, _ = held
    import os
    proc = stairbot("run", "--robot", url, "-q",
                    env={**os.environ, "XDG_STATE_HOME": str(tmp_path / "state")}, cwd=tmp_path)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 1
    (line,) = err.strip().splitlines()
    assert line.startswith(f"stairbot: error: cannot open {url}: serial port ")
    assert "is in use by another stairbot (pid " in line


def test_the_port_is_free_again_once_closed(boards_url: str, monkeypatch: pytest.MonkeyPatch,
                                            tmp_path: Path) -> None:
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))
    for _ in range(2):
        open_robot(boards_url, load_config()).close()
