"""Console defect 9, "two browser tabs, two controllers": each tab of
``console --serve`` is a console process of its own, and a second one on a
robot another holds was refused outright, or (before the lock) commanded it
too.  Now the first console on a robot controls it and shares what it shows;
a second one watches it read-only -- its keys that would reach the robot
say so, its emergency stop goes to the first, which latches it -- until the
first's operator hands control over, never mid-run.

Two consoles in one process here, as two tabs would be two processes: each
opens the robot through the drivers, lock and all."""

from __future__ import annotations

import asyncio
import random
from collections.abc import Iterator
from pathlib import Path

import pytest
from lockstep_boards import fake_boards, lockstep_boards
from pilot import banner, press, ready, said, say_yes, until

from stairbot.console.app import build_app
from stairbot.console.modals import MotionConfirm
from stairbot.console.sharing import share_address


@pytest.fixture
def boards_url(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[str]:
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    with fake_boards(tmp_path) as url:
        # replies waited for 2 s, not 0.05: on a loaded machine the boards'
        # process may not be scheduled in time (lockstep: it never runs ahead)
        yield url + "&timeout=2"


@pytest.mark.parametrize("wire", ["serial", "can"])
def test_a_second_console_watches_the_first_and_cannot_command_it_console_defect_9(
        wire: str, boards_url: str, tmp_path: Path) -> None:
    if wire == "can":  # the same on a CAN bus, locked as a serial port is
        bus = f"udp_multicast/239.74.{random.randrange(1, 255)}.{random.randrange(1, 255)}" \
              f"?port={random.randrange(40000, 60000)}"
        with lockstep_boards(tmp_path, can=bus) as boards:
            watched(boards.url + "&timeout=2")
    else:
        watched(boards_url)


def watched(boards_url: str) -> None:
    async def go() -> None:
        first, second = build_app(url=boards_url), build_app(url=boards_url)
        async with first.run_test(size=(120, 40)) as p1:
            await ready(p1)
            assert share_address(boards_url) is not None
            async with second.run_test(size=(120, 40)) as p2:
                await second.workers.wait_for_complete()
                await until(p2, lambda: "WATCHING" in banner(second), "the second watches")
                assert second.engine.session is None  # it holds no robot
                assert first.engine.session is not None
                await until(p2, lambda: "READY" in banner(second), "the first's state shown")
                assert "another console controls" in said(second)
                # keys that would reach the robot do not
                await press(p2, "s")
                await until(p2, lambda: "watching: another console controls this robot"
                            in said(second), "the refusal")
                assert not second.engine.running and not first.engine.running
                assert not isinstance(first.screen, MotionConfirm)  # nothing asked there
                # the emergency stop goes to the first, which latches it
                await press(p2, "space")
                await until(p1, lambda: first.state.view().status.estopped,
                            "the first latched")
                assert "emergency stop sent to the console that controls the robot" \
                    in said(second)
                await until(p2, lambda: "E-STOP" in banner(second), "the latch shown there")
                assert "emergency stop by the operator (pressed in the console with pid" \
                    in said(first)
    asyncio.run(go())


def test_control_passes_only_when_the_first_hands_it_over(boards_url: str) -> None:
    async def go() -> None:
        first, second = build_app(url=boards_url), build_app(url=boards_url)
        async with first.run_test(size=(120, 40)) as p1:
            await ready(p1)
            async with second.run_test(size=(120, 40)) as p2:
                await second.workers.wait_for_complete()
                await until(p2, lambda: "WATCHING" in banner(second), "the second watches")
                # asked, and kept: nothing changes hands
                await press(p2, "h")
                await until(p1, lambda: isinstance(first.screen, MotionConfirm), "the question")
                await press(p2, "h")  # asked again meanwhile: one question at a time
                await until(p2, lambda: "being asked already" in said(second), "told")
                await press(p1, "escape")
                await until(p2, lambda: "control not handed over: its operator kept control"
                            in said(second), "the refusal told")
                assert first.engine.session is not None and second.engine.session is None
                # a stray y does not hand it over: yes must be typed
                await press(p2, "h")
                await until(p1, lambda: isinstance(first.screen, MotionConfirm), "asked again")
                await press(p1, "y")
                assert first.engine.session is not None
                await press(p1, "e", "s", "enter")
                await until(p2, lambda: second.engine.session is not None, "the second opens")
                await until(p2, lambda: "READY" in banner(second)
                            and "WATCHING" not in banner(second), "the second controls")
                await until(p1, lambda: first.sharing.client is not None
                            and "WATCHING" in banner(first), "the first watches")
                assert first.engine.session is None
                await press(p1, "s")
                await until(p1, lambda: "watching: another console controls this robot"
                            in said(first), "the first's keys refused now")
    asyncio.run(go())


def test_control_is_not_handed_over_mid_run(boards_url: str) -> None:
    async def go() -> None:
        first, second = build_app(url=boards_url), build_app(url=boards_url)
        async with first.run_test(size=(120, 40)) as p1:
            await ready(p1)
            await press(p1, "k")  # calibrate: a wired robot asks first
            await until(p1, lambda: isinstance(first.screen, MotionConfirm), "the question")
            await say_yes(p1)
            await until(p1, lambda: first.engine.running, "the run")
            await press(p1, "p")  # held where it is: the run goes on, paused
            await until(p1, lambda: "PAUSED" in banner(first), "paused")
            async with second.run_test(size=(120, 40)) as p2:
                await second.workers.wait_for_complete()
                await until(p2, lambda: "WATCHING" in banner(second), "the second watches")
                await press(p2, "h")
                await until(p2, lambda: "control not handed over: a run is going on"
                            in said(second), "the refusal, and why")
                assert "asked for control: refused while the run goes on" in said(first)
                assert not isinstance(first.screen, MotionConfirm)
                assert second.engine.session is None and first.engine.running
                await press(p1, "space")
    asyncio.run(go())


def test_a_watched_console_that_closes_leaves_its_values_stale_and_the_robot_free(
        boards_url: str) -> None:
    async def go() -> None:
        # the second outlives the first: it opens the simulation, then (u) the boards
        first, second = build_app(url=boards_url), build_app(url="sim://")
        async with second.run_test(size=(120, 40)) as p2:
            await ready(p2)
            async with first.run_test(size=(120, 40)) as p1:
                await ready(p1)
                second.open_robot(boards_url, None)
                await until(p2, lambda: "WATCHING" in banner(second)
                            and "LIVE" in banner(second), "the second watches")
            # the first quit: what it showed last ages, and nothing claims control
            await until(p2, lambda: "no longer answers" in said(second), "told")
            await until(p2, lambda: "DOWN" in banner(second), "the values go stale")
            assert "(gone)" in second.state.view().watching
            await press(p2, "s")  # no longer refused as watching: there is no robot here
            assert "watching: another console controls" not in said(second)
            second.open_robot(boards_url, None)  # u: the robot opens here now
            await until(p2, lambda: second.engine.session is not None, "opened here")
            await until(p2, lambda: "READY" in banner(second)
                        and "WATCHING" not in banner(second), "controls it")
    asyncio.run(go())


def test_a_third_console_watches_whoever_controls_after_a_handover_red_team(
        boards_url: str) -> None:
    """Finding: a third console was left saying nothing controls the robot."""
    async def go() -> None:
        a, b, c = (build_app(url=boards_url) for _ in range(3))
        async with a.run_test(size=(120, 40)) as pa:
            await ready(pa)
            async with b.run_test(size=(120, 40)) as pb, c.run_test(size=(120, 40)) as pc:
                await b.workers.wait_for_complete()
                await c.workers.wait_for_complete()
                await until(pc, lambda: "WATCHING" in banner(b) and "WATCHING" in banner(c),
                            "both watch")
                await press(pb, "h")
                await until(pa, lambda: isinstance(a.screen, MotionConfirm), "asked")
                await say_yes(pa)
                await until(pb, lambda: b.engine.session is not None
                            and b.sharing.hub is not None, "b controls and shares")
                await until(pc, lambda: c.sharing.client is not None and "watching "
                            "serial" in said(c) and "again" in said(c), "c watches b")
                await until(pc, lambda: "WATCHING" in banner(c) and "READY" in banner(c),
                            "shown so")
                await press(pc, "space")
                await until(pb, lambda: b.state.view().status.estopped, "c's stop reaches b")
    asyncio.run(go())


def test_a_request_never_answers_another_question_nor_outlives_its_asker_red_team(
        boards_url: str) -> None:
    """Findings: a yes typed for "Start calibration" handed control over (the
    request had covered that question); a yes to a request whose console had
    quit closed the robot for no one."""
    async def go() -> None:
        first = build_app(url=boards_url)
        async with first.run_test(size=(120, 40)) as p1:
            await ready(p1)
            second = build_app(url=boards_url)
            async with second.run_test(size=(120, 40)) as p2:
                await second.workers.wait_for_complete()
                await until(p2, lambda: "WATCHING" in banner(second), "watching")
                await press(p1, "k")  # a question of the first's own, open
                await until(p1, lambda: isinstance(first.screen, MotionConfirm), "asked")
                question = first.screen
                await press(p2, "h")
                await until(p2, lambda: "answering another question there" in said(second),
                            "told to ask again")
                assert first.screen is question
                await press(p1, "escape")
                await until(p1, lambda: not isinstance(first.screen, MotionConfirm), "closed")
                await press(p2, "h")
                await until(p1, lambda: isinstance(first.screen, MotionConfirm), "asked now")
            # the asker quit before the answer: yes keeps control here
            await say_yes(p1)
            await until(p1, lambda: "has gone: control kept" in said(first), "told")
            assert first.engine.session is not None and first.sharing.hub is not None
    asyncio.run(go())
