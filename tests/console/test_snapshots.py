"""The layout pinned at 80x24 and 120x40 (pytest-textual-snapshot; update with
``pytest tests/console --snapshot-update`` after checking the new pictures)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
from pilot import said, until
from still_robot import show_climbing
from textual.widgets import Input

from stairbot.console.app import StairbotConsole


async def climbing(pilot: Any) -> None:
    await pilot.app.workers.wait_for_complete()
    show_climbing(pilot.app)
    await pilot.pause(0.3)


@pytest.mark.parametrize("size", [(80, 24), (120, 40)])
def test_layout_while_climbing(snap_compare: Any, still_app: Callable[..., StairbotConsole],
                               size: tuple[int, int]) -> None:
    assert snap_compare(still_app(), terminal_size=size, run_before=climbing)


def test_layout_emergency_stop(snap_compare: Any,
                               still_app: Callable[..., StairbotConsole]) -> None:
    async def stopped(pilot: Any) -> None:
        await climbing(pilot)
        await pilot.press("space")
        # the stop's event reaches the state from the key's handler; then the
        # list redraws on its timer
        await until(pilot, lambda: "emergency stop by the operator" in said(pilot.app),
                    "the e-stop's event")
        await pilot.pause(0.3)
    assert snap_compare(still_app(), terminal_size=(80, 24), run_before=stopped)


def test_layout_wired_robot_confirmation(snap_compare: Any,
                                         still_app: Callable[..., StairbotConsole]) -> None:
    async def asked(pilot: Any) -> None:
        await pilot.app.workers.wait_for_complete()
        await pilot.press("s")
        await pilot.pause(0.3)
        for field in pilot.app.screen.query(Input):  # the same picture whenever it is taken
            field.cursor_blink = False
        await pilot.pause(0.1)
    assert snap_compare(still_app(simulated=False, url="serial://loop://"),
                        terminal_size=(80, 24), run_before=asked)
