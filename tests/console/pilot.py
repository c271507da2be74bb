"""Driving the console in tests: keys sent as the terminal sends them, and
waiting for what the app's threads make true (the bounds only stop a broken
test; no test asserts a time).  A module of its own, not conftest.py."""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from dataclasses import replace
from typing import Any

from textual import events
from textual.geometry import Region
from textual.widgets import Input

from stairbot.console.app import StairbotConsole
from stairbot.hardware import MotorId, Speeds
from stairbot.run.robots import RobotSession, open_robot


async def until(pilot: Any, cond: Callable[[], bool], what: str, *,
                bound_s: float = 60.0) -> None:
    """Let the app run until ``cond`` holds (the bound only stops a broken test:
    a run on fake boards in lockstep, at the speed of a loaded machine, may
    be given more)."""
    for _ in range(int(bound_s / 0.05)):
        if cond():
            await pilot.pause(0.01)
            return
        await asyncio.sleep(0.05)
    raise AssertionError(f"never happened: {what}")


async def press(pilot: Any, *keys: str) -> None:
    """Send key events the way the terminal driver does and let the app handle
    them.  (Pilot.press also waits for the process to go idle, up to 2 s a key,
    which a running simulation never does.)"""
    for key in keys:
        char = " " if key == "space" else (key if len(key) == 1 else None)
        pilot.app.post_message(events.Key(key, char))
        await pilot.pause(0.02)


def banner(app: StairbotConsole) -> str:
    return app.banner.plain


async def say_yes(pilot: Any) -> None:
    """Answer a question that lets the robot move (MotionConfirm): type
    ``yes`` into it, then Enter, and wait until it has closed (its answer's
    callback may start a run before the question leaves the screen: a key
    pressed meanwhile would go into its field)."""
    question = pilot.app.screen
    await press(pilot, "y", "e", "s", "enter")
    await until(pilot, lambda: question not in pilot.app.screen_stack, "the question closes")


async def ready(pilot: Any) -> None:
    await pilot.app.workers.wait_for_complete()
    await until(pilot, lambda: "READY" in banner(pilot.app), "the robot is ready")


async def answer_prompt(pilot: Any, key: str, value: str) -> None:
    """Press ``key``, put ``value`` into the prompt it opens (the URL field
    of the connection manager), press enter."""
    await press(pilot, key)
    await until(pilot, lambda: bool(pilot.app.screen.query(Input)), "the prompt")
    await type_into(pilot, value)


async def type_into(pilot: Any, value: str) -> None:
    """Put ``value`` into the open prompt's field, focused, and press enter."""
    screen = pilot.app.screen
    await until(pilot, lambda: screen.focused is not None, "the prompt's first focus")
    field = screen.query_one(Input)
    field.value = value
    field.focus()
    await until(pilot, lambda: screen.focused is field, "the field focused")
    await press(pilot, "enter")


def shown(widget: Any) -> str:
    """The text a widget shows on screen now (its padding too), lines joined."""
    w, h = widget.outer_size
    return "\n".join(strip.text.rstrip() for strip in widget.render_lines(Region(0, 0, w, h)))


def said(app: StairbotConsole) -> str:
    """Every message in the state's event list (the run's events and what the
    console told the operator), one a line."""
    return "\n".join(event.message for _, event in app.state.view().events)


class SpyRobot:
    """Passes every call to the simulated robot and logs it, so a test can see
    exactly what reached the robot and in which order."""

    def __init__(self, inner: Any) -> None:
        self.inner = inner
        self.calls: list[tuple[str, dict[MotorId, float] | None]] = []

    def read(self) -> Any:
        self.calls.append(("read", None))
        return self.inner.read()

    def command(self, speeds: Speeds) -> None:
        self.calls.append(("command", dict(speeds)))
        self.inner.command(speeds)

    def stop_all(self) -> None:
        self.calls.append(("stop_all", None))
        self.inner.stop_all()

    def estop(self) -> None:
        self.calls.append(("estop", None))
        self.inner.estop()

    def clear(self) -> None:
        self.calls.append(("clear", None))
        self.inner.clear()

    @property
    def estopped(self) -> bool:
        return bool(self.inner.estopped)

    def diagnostics(self) -> dict[str, object]:
        return self.inner.diagnostics()

    def close(self) -> None:
        self.inner.close()

    def motion(self, since: int) -> list[dict[MotorId, float]]:
        """The commands from call ``since`` on that asked some motor to turn."""
        return [c[1] for c in self.calls[since:]
                if c[0] == "command" and c[1] and any(v != 0 for v in c[1].values())]


def spied_open(spies: list[SpyRobot]) -> Callable[..., RobotSession]:
    def open_fn(url: str, config: Any, scenario: Any, options: Any) -> RobotSession:
        session = open_robot(url, config, replace(options, world=scenario))
        spy = SpyRobot(session.robot)
        spies.append(spy)
        return RobotSession(spy, session.clock, session.url, session.simulated, session.sim)
    return open_fn
