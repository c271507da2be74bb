"""The console's top view (key t): the stairwell and the robot seen from above,
in the side view's place at 80x24; a wall contact red and told once; nothing
drawn for a robot that tells no pose seen from above; a pose no longer taken
shown STALE, never as live."""

from __future__ import annotations

import asyncio
import math
import threading
from pathlib import Path
from typing import Any

from pilot import banner, press, ready, said, shown, until
from rich.text import Text
from still_robot import StillClock, StillRobot, StillSim, make_still_app

from stairbot.console.app import COMMANDS, StairbotConsole, build_app
from stairbot.console.help import HELP, WIDTH
from stairbot.console.replay_app import REPLAY_HELP, ReplayConsole
from stairbot.console.state import LiveState
from stairbot.console.watch import watch
from stairbot.console.widgets.top_view import CONTACT_LINE_STYLE
from stairbot.control.robot_config import load_config
from stairbot.errors import LinkLostError
from stairbot.hardware import Snapshot, Truth
from stairbot.inputs.scenario import load_scenario
from stairbot.run.robots import RobotSession
from stairbot.views.top_view import TopPose, plan_of

BRAILLE = {chr(c) for c in range(0x2801, 0x2900)}
README = Path(__file__).parents[2] / "stairbot" / "console" / "README.md"


def drawn(app: StairbotConsole) -> str:
    """The top view's text as rendered (its canvas and caption)."""
    return app.top_view.render().plain


def caption(app: StairbotConsole) -> str:
    """The top view's last line ("" before it has drawn anything: a test waits on)."""
    lines = drawn(app).splitlines()
    return lines[-1] if lines else ""


def title(widget: Any) -> str:
    """A panel's border title as read (Textual keeps it as markup)."""
    return Text.from_markup(str(widget.border_title)).plain


def has_dots(text: str) -> bool:
    return any(ch in BRAILLE for ch in text)


def on_landing(app: StairbotConsole, lateral: float = 0.0, turn_deg: float = 0.0) -> None:
    """Put the simulated robot on landing_left's landing (segment 2's centre
    0.5 m past the top edge, ``lateral`` across), turned ``turn_deg`` left,
    between two of the console's reads (under its lock), and take the pictures."""
    engine = app.engine
    sim: Any = engine.session.sim if engine.session else None
    with engine._lock:
        w = sim.world
        for body in (*w.segments, *w.all_wheels):
            body.position = (body.position.x, body.position.y + 0.51)
        w.shift(0.56 + 0.5 - w.centre_x())
        sim.plan.x, sim.plan.y = w.centre_x(), lateral
        sim.plan.turn(math.radians(turn_deg))
        sim.advance(0.3)
        engine.robot.read()
        engine.robot.refresh_scene()


def landing_app() -> StairbotConsole:
    return build_app(load_config("landings"), scenario="landing_left", speed="max")


def test_at_80x24_t_shows_the_landing_and_the_robot_turned_on_it() -> None:
    async def go() -> None:
        app = landing_app()
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            assert app.picture.display and not app.top_view.display
            await press(pilot, "t")
            assert app.top_view.display and not app.picture.display
            await until(pilot, lambda: "yaw +0°  flight 1" in caption(app), "the start pose")
            assert has_dots(drawn(app))
            assert app.top_view.size.height >= 6 and app.top_view.size.width >= 38
            assert app.log_panel.size.height >= 4  # the event list keeps its rows
            on_landing(app, turn_deg=80.0)
            await until(pilot, lambda: "yaw +80°  flight 2" in caption(app), "turned")
            assert "x +1.06 y +0.00 m" in caption(app)
            assert title(app.top_view).startswith("top view · ")
            assert " ago · sim:// · landing_left" in title(app.top_view)
            assert not app.top_view.has_class("-stale")
            await press(pilot, "t")  # the side view again, in flight 2's frame
            assert app.picture.display and not app.top_view.display
            assert title(app.picture).startswith("side view, flight 2 · ")
    asyncio.run(go())


def test_a_wall_contact_is_red_on_the_wall_and_told_once() -> None:
    async def go() -> None:
        app = landing_app()
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "t")
            on_landing(app, lateral=0.5 - 0.08)  # segment 1 reaches 1 cm into riser 1 of flight 2
            await until(pilot, lambda: "WALL CONTACT" in drawn(app), "the contact")
            assert "segment 1 against riser 1 of flight 2" in " ".join(drawn(app).split())
            rendered = app.top_view.render()
            assert any(str(span.style) == CONTACT_LINE_STYLE for span in rendered.spans)
            await pilot.pause(0.3)
            assert said(app).count("wall contact: segment 1 against riser 1 of flight 2") == 1
    asyncio.run(go())


def test_t_toggles_the_picture_and_brings_it_back_from_the_graphs() -> None:
    async def go() -> None:
        app = make_still_app()
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "g")  # 80x24: the graphs in the picture's place
            assert app.trends.display and not app.picture.display and not app.top_view.display
            await press(pilot, "t")
            assert app.top_view.display and not app.trends.display and not app.picture.display
            await press(pilot, "t")
            assert app.picture.display and not app.top_view.display
        app = make_still_app()
        async with app.run_test(size=(100, 40)) as pilot:  # tall: the graphs stay under it
            await ready(pilot)
            await press(pilot, "t")
            assert app.top_view.display and app.trends.display and not app.picture.display
    asyncio.run(go())


def test_the_help_the_palette_and_the_readme_list_the_key() -> None:
    assert "\n  t       top view" in HELP
    assert all(len(line) <= WIDTH for line in HELP.splitlines())
    assert "\n  t         top view" in REPLAY_HELP
    assert any(action == "top_view" and "(key: t)" in words for action, _t, words in COMMANDS)
    assert "| t | top view" in README.read_text()
    assert any(b.key == "t" and b.action == "top_view" for b in ReplayConsole.BINDINGS)


def test_a_robot_without_a_top_view_shows_nothing_and_says_why() -> None:
    async def go() -> None:
        for simulated, why in ((True, "this robot tells no pose seen from above"),
                               (False, "a robot on a wire tells no pose seen from above")):
            app = make_still_app(simulated=simulated)
            async with app.run_test(size=(80, 24)) as pilot:
                await ready(pilot)
                await press(pilot, "t")
                await until(pilot, lambda app=app, why=why: why in " ".join(drawn(app).split()),
                            "why")
                text = drawn(app)
                assert not has_dots(text)
                assert "top view · none" in title(app.top_view)
                assert why.split()[0] in shown(app.top_view)
    asyncio.run(go())


class TruthfulSim(StillSim):
    """A still simulation that tells its pose seen from above (HasTruth)."""

    def truth(self) -> Truth:
        return Truth(fell=False, fall_reason=None, pitch_deg=0.0, max_pitch_deg=0.0,
                     offset_m=0.0, flight1_x_m=-0.16, flight1_y_m=0.02, flight1_yaw_deg=3.0)


class DyingRobot(StillRobot):
    dead = False

    def read(self) -> Snapshot:
        if self.dead:
            raise LinkLostError("no reply from the sensor board")
        return super().read()


def test_a_pose_no_longer_taken_is_shown_stale() -> None:
    robot, wall = DyingRobot(), [0.0]

    def open_fn(url: str, config: Any, scenario: Any, options: Any) -> RobotSession:
        return RobotSession(robot, StillClock(), url, True, TruthfulSim())

    async def go() -> None:
        app = build_app(load_config(), open_fn=open_fn, ages_wall=lambda: wall[0])
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "t")
            await until(pilot, lambda: "yaw +3°" in caption(app), "the pose")
            assert "0.0 s ago" in title(app.top_view)
            assert not app.top_view.has_class("-stale") and "STALE" not in caption(app)
            robot.dead = True
            await until(pilot, lambda: "FAULT" in banner(app), "the robot lost")
            wall[0] += 5.0
            await until(pilot, lambda: app.top_view.has_class("-stale"), "the view stale")
            assert "STALE 5.0 s" in title(app.top_view)
            assert caption(app).startswith("STALE ")
    asyncio.run(go())


def test_the_pose_keeps_its_own_age_and_a_pose_that_fails_is_dropped() -> None:
    wall = [10.0]
    state = LiveState(wall=lambda: wall[0])
    plan = plan_of(load_scenario("landing_left"))
    state.set_robot("sim://", "landing_left", True, plan=plan)
    assert state.view().plan is plan and state.view().top is None
    state.on_top(TopPose(0.1, 0.0, 0.0))
    wall[0] += 2.0
    v = state.view()
    assert v.top == TopPose(0.1, 0.0, 0.0) and v.top_age_s == 2.0
    state.set_robot("sim://", "default", True)  # another robot: nothing of the last
    assert state.view().plan is None and state.view().top is None

    state.set_robot("sim://", "landing_left", True, plan=plan)
    state.on_top(TopPose(0.1, 0.0, 0.0))

    def broken() -> TopPose | None:
        raise RuntimeError("no truth today")

    robot = watch(StillRobot(), state, threading.RLock(), top=broken)  # type: ignore[arg-type]
    robot.read()
    v = state.view()
    assert v.top is None and v.top_age_s is None  # never the last pose as live
    assert "no top view: no truth today" in v.status.message
