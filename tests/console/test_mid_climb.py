"""Issue 12 item 5, "its latch leaks" (restarting mid-climb): a new run from
where the robot stands is refused once a run has stopped part way up -- the
wheels would grind against the riser for half a minute.  The operator
resumes (boards: the run journal, with `stairbot run --resume`'s checks,
shown where the robot believes it is, nothing moving until confirmed),
resets the simulation, or says the robot is back at the start."""

from __future__ import annotations

import asyncio
import json
import os
import random
from pathlib import Path

import pytest
from lockstep_boards import kill_mid_lift, last_tick, lockstep_boards
from pilot import SpyRobot, banner, press, ready, say_yes, spied_open, until
from textual.widgets import Label

from stairbot.console.app import StairbotConsole, build_app
from stairbot.console.modals import ChoiceScreen, ConfirmScreen
from stairbot.run.journal import read_journal
from stairbot.run.journaled import default_path


def dialog_text(app: StairbotConsole) -> str:
    return "\n".join(str(label.render()) for label in app.screen.query(Label))


def test_a_fresh_start_mid_climb_is_refused_and_reset_is_offered() -> None:
    """Finding: after `x` mid-climb, `s` started a new run from the step."""
    spies: list[SpyRobot] = []

    async def go() -> None:
        app = build_app(speed="10x", open_fn=spied_open(spies))
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")

            def on_a_step() -> bool:
                scene = app.state.view().scene
                return scene is not None and max(scene.segment_steps()) >= 1

            await until(pilot, on_a_step, "a segment over the first tread")
            await press(pilot, "x")
            await until(pilot, lambda: not app.engine.running, "the run stops")
            await app.workers.wait_for_complete()
            spy, n = spies[-1], len(spies[-1].calls)
            await press(pilot, "s")
            await until(pilot, lambda: isinstance(app.screen, ChoiceScreen), "the choice")
            assert "part way up the stairs" in dialog_text(app)
            assert "in: ascent" in dialog_text(app)  # where it stopped
            await press(pilot, "n")
            await until(pilot, lambda: len(app.screen_stack) == 1, "cancelled")
            await pilot.pause(0.2)
            assert not app.engine.running and spy.motion(n) == []
            await press(pilot, "s")
            await until(pilot, lambda: isinstance(app.screen, ChoiceScreen), "the choice")
            await press(pilot, "r")  # reset the simulation: the robot at the start again
            await until(pilot, lambda: len(spies) == 2, "the simulation reopened")
            await app.workers.wait_for_complete()
            await until(pilot, lambda: "READY" in banner(app), "ready")
            assert app.engine.mid_climb is None
            await press(pilot, "s")  # now a fresh run starts at once
            await until(pilot, lambda: app.engine.running, "a fresh run")
            await press(pilot, "x")
            await until(pilot, lambda: not app.engine.running, "stopped")
    asyncio.run(go())


def test_boards_left_mid_climb_resume_from_the_journal_once_confirmed(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Finding: the console let a fresh run start on boards a crashed host had
    left mid-climb; resuming goes by the run journal, as `stairbot run
    --resume` does: where the robot believes it is, then nothing moves
    until the operator confirms."""
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))
    with lockstep_boards(tmp_path) as boards:
        url = boards.url + "&timeout=2"  # a loaded machine may be slow to answer
        journal = default_path(url, boards.identity)
        assert journal is not None
        killed = kill_mid_lift(url, journal, dict(os.environ), tmp_path)

        async def go() -> None:
            app = build_app(url=url)
            async with app.run_test(size=(100, 30)) as pilot:
                await app.workers.wait_for_complete()
                await until(pilot, lambda: "READY" in banner(app)
                            or "stairbot clear" in banner(app), "opened or refused")
                if "stairbot clear" in banner(app):  # the boards' watchdogs tripped
                    await press(pilot, "c")
                    await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "clear?")
                    await press(pilot, "y")
                    await until(pilot, lambda: "READY" in banner(app), "cleared, ready")
                assert app.engine.mid_climb is not None
                await press(pilot, "s")
                await until(pilot, lambda: isinstance(app.screen, ChoiceScreen), "the choice")
                assert "the host stopped in: ascent 3 — lift segment 1" in dialog_text(app)
                await press(pilot, "r")
                await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "resume?")
                text = dialog_text(app)
                assert "last command: MTF +10.00 turn/s" in text
                assert "does it stand where these lines say?" in text
                await press(pilot, "escape")  # not yet: nothing moves
                await until(pilot, lambda: len(app.screen_stack) == 1, "answered")
                await pilot.pause(0.3)
                assert not app.engine.running
                assert last_tick(journal) == killed
                await press(pilot, "s")
                await until(pilot, lambda: isinstance(app.screen, ChoiceScreen), "again")
                await press(pilot, "r")
                await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "resume?")
                await say_yes(pilot)
                await until(pilot, lambda: app.engine.running, "resumed")
                # the rest of five steps up and down over the wire: on a loaded
                # machine, minutes
                await until(pilot, lambda: not app.engine.running, "the run ends", bound_s=600)
                result = app.state.view().result
                assert result is not None
                assert (result.outcome, result.steps_climbed, result.steps_descended) == (
                    "completed", 5, 5)
                assert app.engine.mid_climb is None
        asyncio.run(go())
        records = [json.loads(line) for line in journal.read_text().splitlines()]
        assert [r["kind"] for r in records].count("resume") == 1  # the same run, carried on
        assert records[-1]["kind"] == "end" and records[-1]["outcome"] == "completed"
        assert read_journal(journal).end is not None


def test_a_journal_of_other_boards_on_the_same_url_is_not_offered_console_defect_6(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Finding: on a reused port, the console offered Resume for another
    process's run (the journal was kept by the port alone).  It is kept by
    the motor board's serial number; each launch of the fake boards is a
    robot of its own: boards served again on the same bus are not the
    journal's."""
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))
    bus = f"udp_multicast/239.74.{random.randrange(1, 255)}.{random.randrange(1, 255)}" \
          f"?port={random.randrange(40000, 60000)}"
    with lockstep_boards(tmp_path, can=bus) as first:
        url = first.url + "&timeout=2"
        journal = default_path(url, first.identity)
        assert journal is not None
        kill_mid_lift(url, journal, dict(os.environ), tmp_path, phase="ascent_approach",
                      lift=("MWR", 1))  # driving at the first riser
    with lockstep_boards(tmp_path, can=bus) as second:
        assert second.url == first.url and second.motor_serial != first.motor_serial

        async def go() -> None:
            app = build_app(url=url)
            async with app.run_test(size=(100, 30)) as pilot:
                await app.workers.wait_for_complete()
                await until(pilot, lambda: "READY" in banner(app), "opened")
                assert app.engine.mid_climb is None  # nothing says these boards climbed
                await press(pilot, "s")
                await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "start?")
                assert "part way up" not in dialog_text(app)
                await press(pilot, "escape")
        asyncio.run(go())
    assert read_journal(journal).end is None  # the first boards' run, kept as it was
