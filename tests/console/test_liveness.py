"""Issue 12 item 5, "it can lie": the console never shows a value as live when
it is stale, and says what went wrong where the operator can read it.

* an idle robot is read every POLL_PERIOD_S: a link that dies while idle is
  a FAULT with the driver's reason, not READY with the sensors "ok";
* every panel of values says how old they are; stale ones are dimmed and
  marked STALE;
* boards killed mid-run: FAULT with the driver's reason, not ENDED;
* an automatic stop says why and is told apart from the operator's;
* a bad port at start: its whole reason, on screen and in the event list.
"""

from __future__ import annotations

import asyncio
import signal
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from lockstep_boards import stairbot
from pilot import banner, press, ready, said, say_yes, shown, until
from still_robot import StillClock, StillRobot, make_still_app

from stairbot.console.app import StairbotConsole, build_app
from stairbot.console.modals import ConfirmScreen
from stairbot.console.widgets.banner import message_text
from stairbot.hardware import Imu, Snapshot
from stairbot.run.robots import RobotSession


@pytest.fixture
def boards(tmp_path: Path, monkeypatch: pytest.MonkeyPatch
           ) -> Iterator[tuple[str, subprocess.Popen[str]]]:
    """Fake boards in lockstep (their URL, their process), to be killed."""
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    proc = stairbot("fake-boards", "--serial", "--lockstep", cwd=tmp_path)
    assert proc.stdout is not None
    url = proc.stdout.readline().strip()
    yield url, proc
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        proc.wait(10)


def stale(app: StairbotConsole) -> bool:
    return all(p.has_class("-stale") for p in (app.sensors, app.motors, app.link))


def test_a_link_that_dies_while_idle_is_a_fault_and_its_values_go_stale(
        boards: tuple[str, subprocess.Popen[str]]) -> None:
    """Finding: nothing was read while idle; boards gone showed READY and the
    sensors "ok" for ever."""
    url, proc = boards

    async def go() -> None:
        app = build_app(url=url)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await until(pilot, lambda: " ago" in str(app.sensors.border_title), "an age")
            assert not stale(app)
            proc.kill()
            proc.wait()
            await until(pilot, lambda: "FAULT" in banner(app), "the fault")
            assert "READY" not in banner(app)
            assert "link lost" in banner(app) and "link lost" in said(app)
            await until(pilot, lambda: stale(app), "the values marked stale")
            assert "STALE" in str(app.sensors.border_title)
            assert "STALE" in str(app.motors.border_title)
    asyncio.run(go())


def test_boards_killed_mid_run_are_a_fault_with_the_drivers_reason(
        boards: tuple[str, subprocess.Popen[str]]) -> None:
    """Finding: boards killed mid-run showed "cannot write to the port:
    [Errno 5]" and ENDED, not FAULT (and their last values as if live)."""
    url, proc = boards

    async def go() -> None:
        app = build_app(url=url)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")
            await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "the question")
            await say_yes(pilot)

            def ticks() -> int:
                return app.state.view().ticks

            await until(pilot, lambda: ticks() > 50, "the run goes on")
            proc.kill()
            proc.wait()
            await until(pilot, lambda: not app.engine.running, "the run ends")
            await until(pilot, lambda: "FAULT" in banner(app), "the fault")
            assert "ENDED" not in banner(app)
            assert "link lost" in banner(app)
            await until(pilot, lambda: stale(app), "the values marked stale")
    asyncio.run(go())


class TiltedRobot(StillRobot):
    """Pitched nose up far past the supervisor's limit."""

    def read(self) -> Snapshot:
        snap = super().read()
        return Snapshot(snap.time_s, snap.sensors, snap.motors, snap.health,
                        imu=Imu(30.0, 0.0))


def tilted_open(url: str, config: Any, scenario: Any, options: Any) -> RobotSession:
    return RobotSession(TiltedRobot(), StillClock(), url, True, None)


def test_an_automatic_stop_says_why_and_is_not_an_operator_stop() -> None:
    """Finding: a stop by the supervisor (or any runner fault) looked like an
    operator's stop."""
    async def go() -> None:
        app = build_app(open_fn=tilted_open)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")  # a robot without an in-process world: it asks
            await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "the question")
            await say_yes(pilot)
            await until(pilot, lambda: "E-STOP" in banner(app), "the stop")
            await until(pilot, lambda: not app.engine.running, "the run ends")
            text = banner(app)
            assert "(automatic)" in text and "(operator)" not in text
            assert "tilt" in text.lower() or "pitch" in text.lower()
            assert "emergency stop latched automatically" in said(app)
            assert "by the operator" not in said(app)
    asyncio.run(go())


def test_an_operator_stop_says_so() -> None:
    async def go() -> None:
        app = make_still_app()
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "space")
            await until(pilot, lambda: "E-STOP" in banner(app), "the stop")
            assert "(operator)" in banner(app)
            assert "emergency stop by the operator" in said(app)
    asyncio.run(go())


def test_a_bad_port_at_start_shows_its_whole_reason_and_keeps_it() -> None:
    """Finding: a bad port at start showed its reason cut off at 80 columns,
    or only in a pop-up that went after 6 s."""
    url = "serial:///dev/stairbot-test-no-such-port"

    async def go() -> None:
        app = build_app(url=url)
        async with app.run_test(size=(80, 24)) as pilot:
            await app.workers.wait_for_complete()
            await until(pilot, lambda: "FAULT" in banner(app), "the fault")
            await pilot.pause(0.3)
            message = app.state.view().status.message
            assert message.startswith(f"cannot open {url}: ")
            assert message.endswith("No such file or directory: "
                                    "'/dev/stairbot-test-no-such-port'")
            # whole, wrapped under the strip, which holds the URL
            reason = " ".join(message_text(url, message).plain.split())
            assert reason.startswith("cannot open the robot: cannot open port")
            on_screen = " ".join(shown(app.banner).split())
            assert reason in on_screen
            assert message in said(app)  # and kept in the event list, URL and all
            app.clear_notifications()  # the toast gone, the reason stays
            await pilot.pause(0.2)
            assert reason in " ".join(shown(app.banner).split())
    asyncio.run(go())


def test_the_strip_message_keeps_the_url_of_a_command_to_type() -> None:
    url = "serial:///dev/pts/6"
    shown = message_text(url, f"cannot open {url}: the motor board has its watchdog "
                              f"tripped; check the robot, then `stairbot clear --robot {url}`")
    assert shown.plain == (" cannot open the robot: the motor board has its watchdog "
                           f"tripped; check the robot, then `stairbot clear --robot {url}`")
