"""Issue 12 item 5, "it crashes": text the operator typed (a URL, a path) or
that came from a driver is never parsed as Textual markup -- in toasts,
labels, the banner, border titles, the event list or dialogs.  Before, a
square bracket in it raised MarkupError and the console exited (with
status 0), also mid-run."""

from __future__ import annotations

import asyncio
from pathlib import Path

from pilot import answer_prompt, banner, press, ready, said, until

from stairbot.console.app import build_app

BRACKETS = "[?a=b&c]"


def test_a_url_whose_error_holds_markup_does_not_crash() -> None:
    """Finding: typing `serial://` into the URL prompt crashed the console (its
    error says "expected serial://PORT[?baud=N&timeout=S...]")."""
    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await answer_prompt(pilot, "u", "serial://")
            await until(pilot, lambda: "serial://PORT[?baud=N" in banner(app), "the message")
            await app.workers.wait_for_complete()
            assert "serial://PORT[?baud=N" in said(app)
            await answer_prompt(pilot, "u", f"sim://{BRACKETS}")
            await until(pilot, lambda: BRACKETS in said(app), "the second message")
            await app.workers.wait_for_complete()
            assert app.is_running and app.engine.session is not None
    asyncio.run(go())


def test_a_record_path_with_brackets_mid_run_does_not_crash(tmp_path: Path) -> None:
    """Finding: a record path holding `[?a=b&c]` crashed the console mid-run."""
    path = tmp_path / f"run{BRACKETS}.jsonl"

    async def go() -> None:
        app = build_app(speed="1x")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")
            await until(pilot, lambda: app.engine.running, "the run starts")
            await answer_prompt(pilot, "w", str(path))
            await until(pilot, lambda: str(path) in said(app), "recording said")
            assert app.is_running and app.engine.running
            await until(pilot, lambda: "REC" in banner(app), "REC in the banner")
            await press(pilot, "x")
            await until(pilot, lambda: not app.engine.running, "the run stops")
    asyncio.run(go())
    assert path.exists()


def test_a_scenario_name_with_brackets_in_the_title_and_the_dialogs(
        tmp_path: Path) -> None:
    """The URL and the scenario go into the side view's border title and the
    start question on a wired robot: shown as typed, not parsed."""
    from still_robot import make_still_app

    async def go() -> None:
        app = make_still_app(simulated=False, url=f"serial://loop://{BRACKETS}")
        async with app.run_test(size=(100, 30)) as pilot:
            await ready(pilot)
            assert BRACKETS in str(app.picture.border_title)
            await press(pilot, "s")
            await until(pilot, lambda: len(app.screen_stack) == 2, "the question")
            from textual.widgets import Label
            text = " ".join(str(label.render()) for label in app.screen.query(Label))
            assert BRACKETS in text
            await press(pilot, "escape")
    asyncio.run(go())
