"""Issue 35's closing note: fake boards listed in the connection manager
were driven with the console's config without a word, even when they
simulate another robot (the registry says which).  Now a question names
both robots before anything opens: c keeps the console's config, b uses
the boards' robot's (while they are open), Escape opens nothing."""

from __future__ import annotations

import asyncio
from pathlib import Path
from typing import Any

import pytest
from pilot import press, ready, until
from still_robot import still_open
from test_connection_manager import highlight, open_manager

from stairbot.console.app import StairbotConsole, build_app
from stairbot.console.board_robot import same_robot
from stairbot.console.modals import ChoiceScreen
from stairbot.control.robot_config import load_config
from stairbot.fakes import registry

URL = "serial:///dev/pts/77?lockstep=1"


@pytest.fixture
def own_dirs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    return tmp_path


def console(opened: list[str]) -> StairbotConsole:
    inner = still_open(simulated=True, wired=True)  # fake boards: simulated, on a wire

    def open_fn(url: str, config: Any, scenario: Any, options: Any) -> Any:
        opened.append(url)
        return inner(url, config, scenario, options)
    return build_app(load_config(), open_fn=open_fn)


async def choose(pilot: Any, url: str) -> None:
    screen = await open_manager(pilot)
    await highlight(pilot, screen, url)
    await press(pilot, "enter")
    await until(pilot, lambda: screen not in pilot.app.screen_stack, "the manager closes")


def question(app: StairbotConsole) -> str:
    assert isinstance(app.screen, ChoiceScreen)
    return app.screen.question


def test_boards_of_another_robot_are_named_before_they_open_and_b_uses_theirs(
        own_dirs: Path) -> None:
    heavy, reference = load_config("heavy_middle"), load_config()
    opened: list[str] = []
    with registry.registered(URL, wire="serial", scenario="default", config="heavy_middle",
                             serials="motor board serial 1, sensor board serial 2"):
        async def go() -> None:
            app = console(opened)
            async with app.run_test(size=(100, 30)) as pilot:
                await ready(pilot)
                assert opened == ["sim://"]
                # Escape: nothing opens, and the console says why
                await choose(pilot, URL)
                await until(pilot, lambda: isinstance(app.screen, ChoiceScreen), "asked")
                words = " ".join(question(app).split())
                assert "simulate the heavy_middle robot" in words
                assert "this console's config is the reference robot" in words
                await press(pilot, "escape")
                await until(pilot, lambda: len(app.screen_stack) == 1, "closed")
                await app.workers.wait_for_complete()
                assert opened == ["sim://"] and app.url == "sim://"
                # c: opened with the console's config
                await choose(pilot, URL)
                await until(pilot, lambda: isinstance(app.screen, ChoiceScreen), "asked")
                await press(pilot, "c")
                await until(pilot, lambda: opened[-1] == URL, "opened")
                await app.workers.wait_for_complete()
                assert same_robot(app.engine.config, reference)
                # b: opened with the boards' robot's config
                await choose(pilot, URL)
                await until(pilot, lambda: isinstance(app.screen, ChoiceScreen), "asked")
                await press(pilot, "b")
                await until(pilot, lambda: opened.count(URL) == 2, "opened again")
                await app.workers.wait_for_complete()
                assert same_robot(app.engine.config, heavy)
                assert app.sensors.config is app.engine.config
                assert app.trends.lift_m_per_turn == heavy.motors.lift_travel_per_turn
                # another robot: the console's own config again, no question
                await choose(pilot, "sim://")
                await until(pilot, lambda: opened[-1] == "sim://", "the simulation")
                await app.workers.wait_for_complete()
                assert same_robot(app.engine.config, reference)
                assert app.own_config is None and len(app.screen_stack) == 1
        asyncio.run(go())


def test_boards_of_the_consoles_robot_open_without_a_question(own_dirs: Path) -> None:
    opened: list[str] = []
    with registry.registered(URL, wire="serial", scenario="default", config="reference",
                             serials="motor board serial 1, sensor board serial 2"):
        async def go() -> None:
            app = console(opened)
            async with app.run_test(size=(100, 30)) as pilot:
                await ready(pilot)
                await choose(pilot, URL)
                await until(pilot, lambda: opened[-1] == URL, "opened at once")
                assert not isinstance(app.screen, ChoiceScreen)
        asyncio.run(go())
