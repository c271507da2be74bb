"""The console driven from the keyboard with App.run_test() and the Pilot,
against the real simulated robot and the real run loop."""

from __future__ import annotations

import asyncio
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from pilot import SpyRobot, banner, press, ready, say_yes, spied_open, type_into, until
from still_robot import still_open
from textual.widgets import Input

from stairbot.cli import main as cli_main
from stairbot.console.app import StairbotConsole, build_app
from stairbot.console.modals import ConfirmScreen
from stairbot.errors import LinkLostError
from stairbot.hardware import MotorId, Snapshot
from stairbot.run.robots import RobotSession


def _comparable(line: str) -> dict[str, Any]:
    event = json.loads(line)
    for key in ("wall_time_s", "realtime_factor"):  # the wall clock's, not the run's
        event["data"].pop(key, None)
    return event


def test_a_full_run_started_from_the_keyboard_reaches_the_end(tmp_path: Path) -> None:
    """... and its event record is what `stairbot run --record` writes."""
    record = tmp_path / "console.jsonl"

    async def go() -> None:
        app = build_app(speed="max", record=str(record))
        async with app.run_test(size=(120, 40)) as pilot:
            await ready(pilot)
            at_start = app.picture.render().plain
            assert "steps 0|0|0" in at_start
            await press(pilot, "s")

            def on_a_step() -> bool:
                scene = app.state.view().scene
                return scene is not None and max(scene.segment_steps()) >= 1

            await until(pilot, on_a_step, "a segment over the first tread")
            climbing = app.picture.render().plain
            assert climbing != at_start  # the picture follows the robot
            await until(pilot, lambda: not app.engine.running, "the run ends")
            await app.workers.wait_for_complete()
            await pilot.pause(0.2)
            result = app.state.view().result
            assert result and result.outcome in ("completed", "stopped", "error", "fell")
            text = banner(app)
            assert "ENDED" in text
            assert f"run {result.outcome}" in text
            assert f"climbed {result.steps_climbed}" in text
            assert app.state.view().flow == "end"
            assert "REC" in text
    asyncio.run(go())
    headless = tmp_path / "run.jsonl"
    assert cli_main(["run", "--quiet", "--record", str(headless)]) in (0, 1)
    ours = [_comparable(x) for x in record.read_text().splitlines()]
    theirs = [_comparable(x) for x in headless.read_text().splitlines()]
    assert ours[-1]["kind"] == "summary" and any(e["kind"] == "end" for e in ours)
    assert ours == theirs


def test_estop_key_stops_every_motor_at_once_and_latches() -> None:
    spies: list[SpyRobot] = []

    async def go() -> None:
        app = build_app(speed="10x", open_fn=spied_open(spies))
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")
            spy = spies[-1]
            await until(pilot, lambda: bool(spy.motion(len(spy.calls) - 5)), "the robot moves")
            n_key = len(spy.calls)
            await press(pilot, "space")
            await until(pilot, lambda: app.state.view().status.estopped, "the stop")
            # The key reaches the robot's own estop(), once; from then on
            # nothing moves (that the key handler stops the robot itself, not
            # waiting for the loop's next tick, is test_engine's
            # ..._without_waiting_for_the_next_tick).
            n_stop = next(i for i in range(n_key, len(spy.calls))
                          if spy.calls[i][0] == "estop")
            assert spy.inner.estopped
            sim = app.engine.session.sim  # type: ignore[union-attr]

            def reads_since_stop() -> int:
                return sum(c[0] == "read" for c in spy.calls[n_stop:])

            def truth() -> tuple[Any, Any]:
                with app.engine.robot_lock:
                    return sim.scene(), sim.read()

            # Gravity may still settle the robot for a moment (a stopped motor
            # does not stop a tip onto the next support): look after 25 ticks.
            await until(pilot, lambda: reads_since_stop() > 25, "25 ticks after the stop")
            scene0, snap0 = truth()
            await until(pilot, lambda: reads_since_stop() > 100, "100 ticks after the stop")
            scene1, snap1 = truth()
            # No motion command reached the robot after the stop ...
            assert spy.motion(n_stop) == []
            # ... no motor turns, and the robot stays where it is (within 1 mm).
            for m in MotorId:
                assert snap1.motors[m].speed_tps == pytest.approx(0.0, abs=0.02)
                assert snap1.motors[m].turns == pytest.approx(snap0.motors[m].turns, abs=0.01)
            for a, b in zip(scene0.segments, scene1.segments, strict=True):
                for (ax, ay), (bx, by) in zip(a, b, strict=True):
                    assert abs(ax - bx) < 1e-3 and abs(ay - by) < 1e-3
            assert "E-STOP" in banner(app)
            # Resume is refused until the stop is cleared.
            await press(pilot, "p")
            await until(pilot, lambda: "clear the emergency stop" in banner(app), "refused")
            assert app.state.view().status.estopped
            await press(pilot, "c")  # asks first (tests/console/test_latch.py)
            await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "the question")
            await press(pilot, "y")
            await until(pilot, lambda: not app.state.view().status.estopped, "cleared")
            await until(pilot, lambda: not spy.inner.estopped, "the robot's clear()")
            assert [c[0] for c in spy.calls[n_stop:]].count("estop") == 1
            assert [c[0] for c in spy.calls[n_stop:]].count("clear") == 1
            assert spy.motion(n_stop) == []  # clearing alone moves nothing
            await press(pilot, "p")  # resume
            n_resume = len(spy.calls)
            await until(pilot, lambda: bool(spy.motion(n_resume)), "motion after clear + resume")
            await press(pilot, "x")
            await until(pilot, lambda: not app.engine.running, "the run stops")
    asyncio.run(go())


def test_pause_and_resume() -> None:
    spies: list[SpyRobot] = []

    async def go() -> None:
        app = build_app(speed="10x", open_fn=spied_open(spies))
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")
            spy = spies[-1]
            await until(pilot, lambda: len(spy.calls) > 100, "100 calls")
            await press(pilot, "p")
            await until(pilot, lambda: "PAUSED" in banner(app), "paused")
            n_pause = len(spy.calls)
            await until(pilot, lambda: len(spy.calls) > n_pause + 60, "ticks while paused")
            # From the tick after the pause on, every command is all zeros.
            cmds = [c[1] for c in spy.calls[n_pause + 6:] if c[0] == "command"]
            assert cmds and all(not any(v != 0 for v in (c or {}).values()) for c in cmds)
            t_paused = app.state.view().snapshot.time_s  # type: ignore[union-attr]
            await press(pilot, "p")
            await until(pilot, lambda: "PAUSED" not in banner(app), "resumed")
            n_resume = len(spy.calls)
            await until(pilot, lambda: bool(spy.motion(n_resume)), "motion after resume")
            assert app.state.view().snapshot.time_s > t_paused  # type: ignore[union-attr]
            await press(pilot, "x")
            await until(pilot, lambda: not app.engine.running, "the run stops")
    asyncio.run(go())


@pytest.mark.parametrize(("key", "value", "expect"), [
    ("u", "bogus://nowhere", "unknown scheme 'bogus'"),
    ("u", "sim://with/a/path", "takes no host"),
    ("o", "/no/such/stairs.toml", "cannot read"),
])
def test_invalid_robot_or_scenario_gives_a_message(key: str, value: str, expect: str) -> None:
    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, key)
            await until(pilot, lambda: bool(app.screen.query(Input)), "the prompt")
            await type_into(pilot, value)
            await until(pilot, lambda: expect in banner(app), "the message")
            await app.workers.wait_for_complete()
            await until(pilot, lambda: len(app.screen_stack) == 1, "the prompt closes")
            assert app.state.view().url == "sim://"  # the previous robot is kept
            assert app.engine.session is not None
            await press(pilot, "s")  # and still runs
            await until(pilot, lambda: app.engine.running or "ENDED" in banner(app), "a run")
            await press(pilot, "x")
            await until(pilot, lambda: not app.engine.running, "the run stops")
    asyncio.run(go())


@pytest.mark.parametrize("boards_say_simulated", [False, True], ids=["real", "fake boards"])
def test_starting_a_wired_robot_asks_first(still_app: Callable[..., StairbotConsole],
                                           boards_say_simulated: bool) -> None:
    """Fake boards are asked about too: their flag is only their own word."""
    async def go() -> None:
        app = still_app(simulated=boards_say_simulated, wired=True, url="serial://loop://")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            robot = app.engine.session.robot  # type: ignore[union-attr]
            await press(pilot, "s")
            await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "the question")
            await press(pilot, "escape")
            await until(pilot, lambda: len(app.screen_stack) == 1, "the answer")
            await pilot.pause(0.1)
            assert not app.engine.running and robot.commands == []
            await press(pilot, "s")
            await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "the question")
            await say_yes(pilot)
            await until(pilot, lambda: len(robot.commands) > 0, "the run starts")
            await press(pilot, "x")
            await until(pilot, lambda: not app.engine.running, "the run stops")
    asyncio.run(go())


def test_estop_key_works_over_a_text_prompt(still_app: Callable[..., StairbotConsole]) -> None:
    async def go() -> None:
        app = still_app()
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")
            await until(pilot, lambda: app.engine.running, "the run starts")
            await press(pilot, "w")  # the record prompt: allowed during a run
            await until(pilot, lambda: bool(app.screen.query(Input)), "the prompt")
            robot = app.engine.session.robot  # type: ignore[union-attr]
            stops = robot.stops
            await press(pilot, "space")
            await until(pilot, lambda: app.state.view().status.estopped, "the stop")
            assert robot.stops > stops
            assert " " not in app.screen.query_one(Input).value
            await press(pilot, "escape")
            await press(pilot, "x")
            await until(pilot, lambda: not app.engine.running, "the run stops")
    asyncio.run(go())


def test_a_lost_link_shows_as_a_banner_not_a_traceback(
        still_app: Callable[..., StairbotConsole]) -> None:
    async def go() -> None:
        app = still_app()
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            robot = app.engine.session.robot  # type: ignore[union-attr]
            reads = 0
            still_read = robot.read

            def failing_read() -> Snapshot:
                nonlocal reads
                reads += 1
                if reads > 20:
                    raise LinkLostError("motor board: no reply to 3 attempts")
                return still_read()

            robot.read = failing_read
            await press(pilot, "s")
            # A lost link is a fault of the robot, not an ordinary ending.
            await until(pilot, lambda: "FAULT" in banner(app), "the run ends in FAULT")
            assert "ENDED" not in banner(app)
            assert "no reply to 3 attempts" in banner(app)
            # the run latched the emergency stop, and the banner says it did
            assert "E-STOP  (automatic)" in banner(app) and "-estop" in app.banner.classes
            assert robot.stops > 0  # the runner stopped every motor
            await pilot.pause(0.2)
            # The run ended between two ticks: the phase panel still shows the end.
            view = app.state.view()
            assert view.flow == "end" and view.phase.startswith("end")
    asyncio.run(go())


def test_a_robot_that_fails_to_reopen_is_named_in_the_banner() -> None:
    """A bad URL closes the robot that was open; when that one cannot be opened
    again either, the banner says so (not a stale "connecting")."""
    opened: list[str] = []

    def open_once(url: str, config: Any, scenario: Any, options: Any) -> RobotSession:
        opened.append(url)
        if len(opened) > 1:
            raise LinkLostError(f"{url}: no reply")
        return still_open(simulated=False)(url, config, scenario, options)

    async def go() -> None:
        app = build_app(url="serial://first", open_fn=open_once)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "u")
            await until(pilot, lambda: bool(app.screen.query(Input)), "the prompt")
            await type_into(pilot, "serial://second")
            await until(pilot, lambda: "did not reopen" in banner(app), "the message")
            text = banner(app)
            assert "FAULT" in text and "serial://second: no reply" in text
            assert opened == ["serial://first", "serial://second", "serial://first"]
            assert app.engine.session is None
    asyncio.run(go())


def test_speed_reset_palette_and_resize() -> None:
    async def go() -> None:
        app = build_app(speed="1x")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            assert app.engine.clock is not None
            for speed in ("10x", "max", "1x"):
                await press(pilot, "f")
                await until(pilot, lambda s=speed: app.state.view().speed == s, speed)
            await press(pilot, "f")
            await press(pilot, "s")
            def sim_time() -> float:
                snap = app.state.view().snapshot
                return snap.time_s if snap is not None else 0.0

            await until(pilot, lambda: sim_time() > 3.0, "3 s of simulated time")
            await press(pilot, "x")
            await until(pilot, lambda: not app.engine.running, "the run stops")
            await press(pilot, "r")  # back to the scenario's start
            await until(pilot, lambda: sim_time() == 0.0, "the reset")
            titles = {c.title for c in app.get_system_commands(app.screen)}
            for title in ("EMERGENCY STOP", "Clear emergency stop", "Start full run",
                          "Calibrate only", "Pause / resume", "Reset the simulated scenario",
                          "Connect to a robot", "Choose scenario", "Simulation speed",
                          "Record events"):
                assert title in titles
            for size in ((120, 40), (80, 24), (100, 30)):
                await pilot.resize_terminal(*size)
                await pilot.pause(0.2)
                lines = app.picture.render().plain.splitlines()
                assert len(lines) == app.picture.size.height
                assert "steps 0|0|0" in lines[-1]
    asyncio.run(go())


def test_calibrate_only_from_the_command_palette() -> None:
    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            (command,) = [c for c in app.get_system_commands(app.screen)
                          if c.title == "Calibrate only"]
            await command.callback()  # what the palette runs when the line is chosen
            await until(pilot, lambda: "ENDED" in banner(app), "the calibration ends")
            result = app.state.view().result
            assert result is not None and result.steps_climbed == 0
            assert result.ascent_end is None
            assert f"run {result.outcome}" in banner(app)
    asyncio.run(go())
