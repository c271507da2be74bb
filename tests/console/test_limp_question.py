"""Issue 33, "the console shows the degraded descent and asks for consent":
a sensor lost mid-climb during a console run makes a degraded stop, which
the console shows plainly and asks about -- come home on the remaining
sensors, or stay stopped -- instead of ending on the sensor error with a
command for another program.  Before, the run ended there and only a
confirmed resume (boards) could carry it on."""

from __future__ import annotations

import asyncio
import re
from pathlib import Path

import lost_sensor
import pytest
from lockstep_boards import lockstep_boards
from pilot import SpyRobot, banner, press, ready, said, say_yes, shown, spied_open, until
from simrun import run_sim
from textual.widgets import Label

from stairbot.console import limp_gate
from stairbot.console.app import StairbotConsole, build_app
from stairbot.console.limp_question import LimpQuestion, StopNotice
from stairbot.console.modals import ChoiceScreen, ConfirmScreen
from stairbot.console.state import LiveState
from stairbot.console.widgets.banner import CUT
from stairbot.control.robot_config import load_config
from stairbot.events import Event
from stairbot.inputs.scenario import parse_scenario
from stairbot.run.journal import read_journal
from stairbot.run.journaled import default_path
from stairbot.run.resume import ResumeRefused

LOST_MID_CLIMB = 'name = "sfr-lost-ascent7"\n' + lost_sensor.LOST_MID_CLIMB

BOTH_BACK_LOST = 'name = "both-back-lost"\n' + lost_sensor.TWO_STEPS + """
[[faults]]
at = 111.1
sensor = "SBR"
kind = "error"
[[faults]]
at = 111.1
sensor = "SBL"
kind = "error"
"""


def scenario(tmp_path: Path, text: str = LOST_MID_CLIMB) -> str:
    path = tmp_path / "lost.toml"
    path.write_text(text, "utf-8")
    return str(path)


def dialog(app: StairbotConsole) -> str:
    return "\n".join(str(label.render()) for label in app.screen.query(Label))


def outcome(app: StairbotConsole) -> str | None:
    result = app.state.view().result
    return None if result is None else result.outcome


async def the_question(pilot: object, app: StairbotConsole) -> None:
    await ready(pilot)
    await press(pilot, "s")
    await until(pilot, lambda: isinstance(app.screen, LimpQuestion), "the limp-home question")


def test_the_degraded_stop_is_shown_and_consent_carries_the_run_home(tmp_path: Path) -> None:
    spies: list[SpyRobot] = []

    async def go() -> None:
        app = build_app(scenario=scenario(tmp_path), speed="max", open_fn=spied_open(spies))
        async with app.run_test(size=(80, 24)) as pilot:
            await the_question(pilot, app)
            text = dialog(app)
            for words in ("DEGRADED STOP at 43.2 s: SFR 3 measurements in a row report an "
                          "error", "ascent 7 — lift segment 3 (step 1)",
                          "finishing step 1, then down the 1 step(s) climbed",
                          "on SFL for the front pair", "at most 50% of its speed"):
                assert words in text, text
            # MTB's counter as the stop read it: segment 3 part way up
            assert re.search(r"the lifts hold: MTF \+0\.0 turns \(\+0 mm\), "
                             r"MTB -\d+\.\d turns \(-\d+ mm\)", text), text
            # the banner repaints on the stop's event, which may come a frame after the question
            await until(pilot, lambda: "DEGRADED STOP" in banner(app), "the banner's stop")
            assert "run error" not in banner(app)
            spy = spies[-1]
            assert spy.inner.estopped  # stopped, latched, while it asks
            await say_yes(pilot)
            await until(pilot, lambda: app.engine.running and bool(app.state.view().limping),
                        "limping home")
            await press(pilot, "p")  # held, to look at the screen while it limps
            await until(pilot, lambda: app.state.view().status.paused, "paused")
            await pilot.pause(0.3)
            assert "SFR out: front pair on SFL · 50% speed" in banner(app)
            assert "DEGRADED" in banner(app)
            sensors = shown(app.sensors)
            assert "LOST" in sensors and "runs on" in sensors, sensors
            assert "LIMPING HOME" in str(app.phase.border_title)
            await press(pilot, "p")
            await until(pilot, lambda: not app.engine.running, "home")
            await app.workers.wait_for_complete()
            await pilot.pause(0.2)
            result = app.state.view().result
            assert result is not None
            assert (result.outcome, result.steps_climbed, result.steps_descended) == (
                "came_home_degraded", 1, 1)
            assert "run came_home_degraded" in banner(app)
            assert "WITHOUT SFR" in banner(app) and "DEGRADED" in banner(app)
            assert "CAME HOME DEGRADED" in str(app.phase.border_title)
            assert app.engine.mid_climb is None  # home: a new run may start
            assert not spy.inner.estopped
    asyncio.run(go())


def test_refusing_leaves_the_robot_stopped_and_says_how_to_bring_it_home(
        tmp_path: Path) -> None:
    spies: list[SpyRobot] = []

    async def go() -> None:
        app = build_app(scenario=scenario(tmp_path), speed="max", open_fn=spied_open(spies))
        async with app.run_test(size=(80, 24)) as pilot:
            await the_question(pilot, app)
            spy = spies[-1]
            n = len(spy.calls)
            await press(pilot, "escape")
            await until(pilot, lambda: not isinstance(app.screen, LimpQuestion), "answered")
            await pilot.pause(0.5)
            assert spy.motion(n) == [] and spy.inner.estopped and not app.engine.running
            assert "stays stopped, lifts holding" in banner(app)
            assert "l asks again" in banner(app)
            assert "not moved (stay stopped)" in said(app)
            # later: l asks again; or, the stop's latch cleared (c), s offers it
            await press(pilot, "l")
            await until(pilot, lambda: isinstance(app.screen, LimpQuestion), "asked again")
            await press(pilot, "escape")
            await until(pilot, lambda: len(app.screen_stack) == 1, "refused again")
            await press(pilot, "c")
            await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "clear?")
            await press(pilot, "y")
            await until(pilot, lambda: not app.state.view().status.estopped, "cleared")
            assert spy.motion(n) == []
            await press(pilot, "s")
            await until(pilot, lambda: isinstance(app.screen, ChoiceScreen), "the choices")
            assert "Limp home asks whether it may come down" in dialog(app)
            await press(pilot, "l")
            await until(pilot, lambda: isinstance(app.screen, LimpQuestion), "asked from s")
            await say_yes(pilot)
            await until(pilot, lambda: outcome(app) == "came_home_degraded",
                        "came home degraded")
    asyncio.run(go())


@pytest.mark.parametrize("key", ["ctrl+c", "ctrl+q"])
def test_quitting_at_the_question_leaves_the_robot_stopped(tmp_path: Path, key: str) -> None:
    spies: list[SpyRobot] = []

    async def go() -> None:
        app = build_app(scenario=scenario(tmp_path), speed="max", open_fn=spied_open(spies))
        async with app.run_test(size=(80, 24)) as pilot:
            await the_question(pilot, app)
            spy = spies[-1]
            n = len(spy.calls)
            await press(pilot, key)
            await until(pilot, lambda: not app.is_running, "the console quits")
        assert spy.motion(n) == [] and spy.inner.estopped
        assert ("stop_all", None) in spy.calls[n:]
    asyncio.run(go())


def test_the_emergency_stop_withdraws_the_question(tmp_path: Path) -> None:
    spies: list[SpyRobot] = []

    async def go() -> None:
        app = build_app(scenario=scenario(tmp_path), speed="max", open_fn=spied_open(spies))
        async with app.run_test(size=(80, 24)) as pilot:
            await the_question(pilot, app)
            spy = spies[-1]
            n = len(spy.calls)
            await press(pilot, "space")
            await until(pilot, lambda: not isinstance(app.screen, LimpQuestion), "withdrawn")
            await press(pilot, "l")  # not asked again while the operator's stop is set
            await pilot.pause(0.5)
            assert not isinstance(app.screen, LimpQuestion)
            assert "c clears it" in said(app)
            assert spy.motion(n) == [] and not app.engine.running
    asyncio.run(go())


def test_too_little_left_to_come_down_on_is_said_not_asked(tmp_path: Path) -> None:
    async def go() -> None:
        app = build_app(scenario=scenario(tmp_path, BOTH_BACK_LOST), speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")
            await until(pilot, lambda: isinstance(app.screen, StopNotice), "the notice")
            text = dialog(app)
            assert "DEGRADED STOP" in text and "No question to ask" in text, text
            assert "both back sensors lost" in text, text
            assert app.engine.limp_offer is None
            await press(pilot, "enter")
            await until(pilot, lambda: len(app.screen_stack) == 1, "read")
            await press(pilot, "l")
            await pilot.pause(0.3)
            assert "no degraded stop to limp home from" in said(app)
    asyncio.run(go())


def test_the_limp_is_followed_by_the_run_events_alone_as_a_replay_has_them() -> None:
    """A replay (or a JSON-lines record) has the events and no context: the
    stop, the limp and a new program's start are told by them."""
    events: list[Event] = []
    result = run_sim(load_config(), parse_scenario(LOST_MID_CLIMB, "<lost>"), events,
                     limp_home=True)
    assert result.outcome == "came_home_degraded"
    state = LiveState()
    limping_from = None
    for event in events:
        state.on_event(event)
        if limping_from is None and state.view().limping:
            limping_from = event.time_s
    view = state.view()
    assert view.limping == ("SFR",) and view.degraded is not None
    assert view.degraded.data["degraded"]["then"] == "limp_home"
    assert limping_from == view.degraded.time_s  # from the stop on
    assert view.limp_end == "came_home_degraded"
    state.on_event(next(e for e in events if e.data.get("why") == "program start"))
    assert state.view().limping == () and state.view().degraded is None  # a new run


def test_boards_come_home_from_the_question_through_their_journal(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Boards on a wire: the consent carries the journal's run on, as
    `stairbot run --resume --yes` would, in the same console."""
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))
    path = scenario(tmp_path)
    with lockstep_boards(tmp_path, scenario=path) as served:
        journal = default_path(served.url, served.identity)
        assert journal is not None

        async def go() -> None:
            app = build_app(url=served.url, scenario=path)
            async with app.run_test(size=(80, 24)) as pilot:
                await ready(pilot)
                await press(pilot, "s")
                await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "start?")
                await say_yes(pilot)
                await until(pilot, lambda: isinstance(app.screen, LimpQuestion)
                            or outcome(app) is not None, "the question", bound_s=600)
                await app.workers.wait_for_complete()  # the run's worker asks at its end
                assert isinstance(app.screen, LimpQuestion), app.state.view().result
                assert "(boards on a wire)" in dialog(app)
                end = read_journal(journal).end
                assert end is not None and end["resumable"] is True
                await say_yes(pilot)
                await until(pilot, lambda: outcome(app) == "came_home_degraded", "home",
                            bound_s=600)
        asyncio.run(go())
    end = read_journal(journal).end
    assert end is not None and end["outcome"] == "came_home_degraded", end


def test_no_question_when_the_console_cannot_carry_the_run_on(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Boards whose journal no longer checks (here: made to refuse) cannot be
    carried on: the stop is told, and no question asked."""
    def refused(*_args: object) -> None:
        raise ResumeRefused("the boards restarted since the journal")

    monkeypatch.setattr(limp_gate, "offer_after", refused)

    async def go() -> None:
        app = build_app(scenario=scenario(tmp_path), speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")
            await until(pilot, lambda: isinstance(app.screen, StopNotice), "the notice")
            text = dialog(app)
            assert "this console cannot carry the run on (the boards restarted" in text, text
            await until(pilot, lambda: "cannot carry the run on" in app.state.view().status.message,
                        "the banner's message")
            # at 80x24 the banner holds four lines of it; the rest in the events
            await until(pilot, lambda: "cannot carry the run on" in banner(app)
                        or banner(app).endswith(CUT) and app.state.view().status.message
                        in said(app), "the banner, or the whole in the events")
            assert "stairbot run --resume --yes" not in app.state.view().status.message
    asyncio.run(go())
