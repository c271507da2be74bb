"""Issue 35, "parameters in view": ``i`` shows the resolved robot config
(units, the config that set each value) and the limits the controller works
from; between runs a runtime-safe value changes through a checked diff into
a new ``extends`` file, never over one, which the next run uses while the
simulation's world stays the robot it was opened as."""

from __future__ import annotations

import asyncio
from dataclasses import replace
from pathlib import Path
from typing import Any

import msgspec
import pytest
from pilot import banner, press, ready, said, until
from textual.widgets import Input, Tree

from stairbot.console.app import StairbotConsole, build_app
from stairbot.console.param_edit import Parameters
from stairbot.console.params import Limit, Value, shown_value, values
from stairbot.console.params_screen import MID_RUN, DiffScreen, ParamsScreen
from stairbot.control.algorithm import limits
from stairbot.control.algorithm.phases import Mode
from stairbot.control.robot_config import load_config
from stairbot.errors import InputError
from stairbot.inputs.config import RobotConfig
from stairbot.run.robots import RobotSession, open_robot
from stairbot.run.runner import run


@pytest.fixture
def config_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """$XDG_CONFIG_HOME for the test: where changes to a shipped robot go."""
    home = tmp_path / "xdg"
    monkeypatch.setenv("XDG_CONFIG_HOME", str(home))
    return home / "stairbot"


def leaves(app: StairbotConsole) -> dict[str, Any]:
    """The tree's leaves by key (a config value) or name (a derived limit),
    each with its label as shown."""
    tree = app.screen.query_one(Tree)
    out: dict[str, Any] = {}
    todo = [tree.root]
    while todo:
        node = todo.pop()
        todo.extend(node.children)
        if isinstance(node.data, Value):
            out[node.data.key] = (node.data, str(node.label))
        elif isinstance(node.data, Limit):
            out[node.data.name] = (node.data, str(node.label))
    return out


def message(app: StairbotConsole) -> str:
    return str(app.screen.query_one("#params-say").render())


def editing(app: StairbotConsole) -> bool:
    return app.screen.query_one("#params-edit-row").has_class("editing")


async def open_params(pilot: Any) -> ParamsScreen:
    await press(pilot, "i")
    await until(pilot, lambda: isinstance(pilot.app.screen, ParamsScreen), "the screen")
    screen = pilot.app.screen
    assert isinstance(screen, ParamsScreen)
    return screen


async def choose(pilot: Any, key: str) -> None:
    """Put the tree's cursor on ``key`` and press Enter on it."""
    screen = pilot.app.screen
    assert isinstance(screen, ParamsScreen)
    screen.show_key(key)
    await pilot.pause(0.05)
    tree = screen.query_one(Tree)
    assert tree.cursor_node is not None and tree.cursor_node.data.key == key
    await press(pilot, "enter")


async def type_value(pilot: Any, text: str) -> None:
    await until(pilot, lambda: editing(pilot.app), "the field")
    pilot.app.screen.query_one("#params-edit", Input).value = text
    await press(pilot, "enter")


def test_the_tree_shows_the_default_config_and_the_controllers_limits(
        config_home: Path) -> None:
    cfg = load_config()

    async def go() -> None:
        app = build_app(cfg, speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await open_params(pilot)
            shown = leaves(app)
            value, label = shown["motors.wheel_speed"]
            assert value.value == 1.0 and value.unit == "turns/s"
            assert "1 turns/s" in label and "✎" in label and "reference (shipped)" in label
            assert "✎" not in shown["geometry.wheel_radius"][1]
            assert "0.016 m" in shown["geometry.wheel_radius"][1]
            rise, label = shown["max_step_rise_m"]
            assert rise.value == limits.derived(cfg)["max_step_rise_m"] == cfg.max_step_rise_m
            assert shown_value(rise.value) in label and label.endswith(" m")
            timeout, _ = shown["phase_timeout_s"]
            from stairbot.control.algorithm.guards import phase_timeout_s
            assert timeout.value == phase_timeout_s(cfg)
    asyncio.run(go())


def test_each_value_says_which_config_of_the_chain_set_it(tmp_path: Path) -> None:
    mine = tmp_path / "robot.toml"
    mine.write_text('extends = "reference"\n[motors]\nwheel_speed = 0.8\n')

    async def go() -> None:
        app = build_app(str(mine), speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await open_params(pilot)
            shown = leaves(app)
            assert shown["motors.wheel_speed"][0].source == str(mine)
            assert shown["motors.lift_speed"][0].source == "reference (shipped)"
            assert shown["geometry.LENGTH_OF_A_ROBOT"][0].source == "the schema's default"
    asyncio.run(go())


def test_an_edit_mid_run_is_refused(config_home: Path) -> None:
    async def go() -> None:
        app = build_app(speed="1x")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")
            await until(pilot, lambda: app.engine.running, "the run goes")
            await open_params(pilot)
            await choose(pilot, "motors.wheel_speed")
            await until(pilot, lambda: MID_RUN in message(app), "the refusal")
            assert not editing(app)
            assert MID_RUN in said(app)
            await press(pilot, "escape", "x")
            await until(pilot, lambda: not app.engine.running, "the run stops")
        assert app.engine.config.motors.wheel_speed == 1.0
    asyncio.run(go())
    assert not config_home.exists()


def test_a_bad_value_is_refused_with_what_is_allowed_and_nothing_written(
        config_home: Path) -> None:
    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await open_params(pilot)
            await choose(pilot, "motors.wheel_speed")
            await type_value(pilot, "2")  # faster than the motors it started with
            await until(pilot, lambda: "not changed" in message(app), "the refusal")
            assert "motors.wheel_speed" in message(app)
            assert "from 0.5 to 1 turns/s" in message(app)
            await type_value(pilot, "0.3")  # slower than half: its timeouts would stretch
            await until(pilot, lambda: "0.3 is not allowed" in message(app), "too slow")
            assert "from 0.5 to 1 turns/s" in message(app)
            await type_value(pilot, "fast")
            await until(pilot, lambda: "'fast' is not allowed" in message(app), "refused")
            assert not isinstance(app.screen, DiffScreen)
            await press(pilot, "escape")
            await choose(pilot, "motors.lift_speed")
            await type_value(pilot, "0.05")  # less than half the lifts' speed
            await until(pilot, lambda: "from 5 to 10 turns/s" in message(app), "refused")
            assert "motors.lift_speed" in message(app)
            assert not isinstance(app.screen, DiffScreen)
            await press(pilot, "escape")
            await choose(pilot, "safety.stability_margin")
            await type_value(pilot, "0.5")  # the config checks: no room on the middle wheels
            await until(pilot, lambda: "leaves no room" in message(app), "refused")
            assert "safety.stability_margin" in message(app)
            assert not isinstance(app.screen, DiffScreen)
        assert app.engine.config.motors == load_config().motors
    asyncio.run(go())
    assert not config_home.exists()


def test_a_good_edit_shows_a_diff_then_writes_an_extends_file_the_next_run_uses(
        config_home: Path) -> None:
    """Enter alone keeps the old value (the focus starts on "Keep the old");
    Tab to "Use it" and Enter writes the file beside the one already there,
    and the next run (calibration only, here) runs on it while the
    simulation is reopened with the robot it was opened as."""
    config_home.mkdir(parents=True)
    taken = config_home / "reference-params.toml"
    taken.write_text("# not the console's\n")
    used: list[RobotConfig] = []
    opened: list[RobotConfig] = []

    def open_fn(url: str, config: RobotConfig, scenario: Any, options: Any) -> RobotSession:
        opened.append(config)
        return open_robot(url, config, replace(options, world=scenario))

    def run_fn(session: RobotSession, config: RobotConfig, sink: Any, mode: str,
               control: Any, on_tick: Any, plan: Any) -> Any:
        used.append(config)
        return run(session, config, sink, Mode.CALIBRATE_ONLY, control, on_tick=on_tick)

    async def go() -> Path:
        app = build_app(speed="max", open_fn=open_fn, run_fn=run_fn)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await open_params(pilot)
            await choose(pilot, "motors.wheel_speed")
            await type_value(pilot, "0.5")
            await until(pilot, lambda: isinstance(app.screen, DiffScreen), "the diff")
            diff = app.screen
            assert isinstance(diff, DiffScreen)
            text = str(diff.query_one("#diff-text").render())
            assert 'extends = "reference"' in text and "wheel_speed = 0.5" in text
            summary = diff.summary()
            assert "motors.wheel_speed  1 → 0.5" in summary
            assert "wheel_speed_m_s" in summary
            await press(pilot, "enter")  # on "Keep the old"
            await until(pilot, lambda: isinstance(app.screen, ParamsScreen), "kept")
            assert sorted(config_home.iterdir()) == [taken]
            assert app.engine.config.motors.wheel_speed == 1.0
            await choose(pilot, "motors.wheel_speed")
            await type_value(pilot, "0.5")
            await until(pilot, lambda: isinstance(app.screen, DiffScreen), "the diff")
            await press(pilot, "tab", "enter")  # "Use it"
            await until(pilot, lambda: app.engine.config.motors.wheel_speed == 0.5,
                        "the new config taken")
            written = config_home / "reference-params-1.toml"
            assert f"the next run uses {written}" in said(app)
            assert str(written) in str(app.screen.query_one("#params-title").render())
            assert f"the next run uses {written}" in app.state.view().status.message
            await press(pilot, "escape", "k")
            await until(pilot, lambda: "ENDED" in banner(app), "the calibration ends")
            await press(pilot, "r")  # the simulation reopened at the scenario's start
            await until(pilot, lambda: len(opened) == 2, "reopened")
            await ready(pilot)
        return written

    written = asyncio.run(go())
    assert taken.read_text() == "# not the console's\n"
    back = load_config(written)
    assert back == replace(load_config(), source=str(written),
                           motors=msgspec.structs.replace(load_config().motors,
                                                          wheel_speed=0.5))
    assert [c.motors.wheel_speed for c in used] == [0.5]
    assert used[0].source == str(written)
    assert [c.motors.wheel_speed for c in opened] == [1.0, 1.0]  # the world's motors


def test_a_change_to_a_users_file_is_written_beside_it(tmp_path: Path) -> None:
    mine = tmp_path / "robot.toml"
    mine.write_text('extends = "reference"\n[algorithm]\nmax_steps = 4\n')
    params = Parameters(load_config(str(mine)))
    change = params.propose(load_config(str(mine)), "algorithm.max_steps", "2")
    assert change.path == tmp_path / "robot-params.toml"
    path = params.write(change)
    assert path == tmp_path / "robot-params.toml"
    assert f'extends = "{mine}"' in path.read_text()
    assert load_config(path).algorithm.max_steps == 2
    again = params.propose(load_config(path), "safety.max_pitch_deg", "12")
    assert again.path == tmp_path / "robot-params-1.toml"  # never over the first
    assert again.overrides == {"algorithm.max_steps": 2, "safety.max_pitch_deg": 12.0}
    assert f'extends = "{mine}"' in again.text  # one file deep, whatever the changes
    again.path.write_text("# written meanwhile\n")  # the name taken after the check
    assert params.write(again) == tmp_path / "robot-params-2.toml"
    assert again.path.read_text() == "# written meanwhile\n"
    assert load_config(tmp_path / "robot-params-2.toml").safety.max_pitch_deg == 12.0


def test_a_parameter_that_is_not_runtime_safe_cannot_be_edited(config_home: Path) -> None:
    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await open_params(pilot)
            await choose(pilot, "geometry.wheel_radius")
            await until(pilot, lambda: "not runtime-safe" in message(app), "the refusal")
            assert not editing(app)
    asyncio.run(go())
    with pytest.raises(InputError, match="not runtime-safe"):
        Parameters(load_config()).propose(load_config(), "sensors.front_height", "0.05")
    assert not config_home.exists()


def test_a_file_changed_since_it_was_loaded_shows_no_sources(tmp_path: Path) -> None:
    """Where each value came from is read again from the chain's files: once
    they no longer resolve to the config the console holds, no source is
    shown, and the screen says why, rather than name a file that now says
    otherwise."""
    mine = tmp_path / "robot.toml"
    mine.write_text('extends = "reference"\n[motors]\nwheel_speed = 0.8\n')
    cfg = load_config(str(mine))
    assert values(cfg)[1] == ""
    mine.write_text('extends = "reference"\n[motors]\nwheel_speed = 0.6\n')
    rows, note = values(cfg)
    assert all(v.source is None for v in rows)
    assert f"{mine} changed since it was loaded" in note
    assert next(v for v in rows if v.key == "motors.wheel_speed").value == 0.8


def test_an_edit_over_a_user_file_changed_since_the_start_is_refused(tmp_path: Path) -> None:
    # the file the console started on loosens a threshold and speeds a lift
    # up afterwards; a change of another value must not carry that into a run
    base = tmp_path / "mine.toml"
    base.write_text('extends = "reference"\n')
    started = load_config(base)
    params = Parameters(started)
    base.write_text('extends = "reference"\n[safety]\nmax_pitch_deg = 30\n'
                    '[motors]\nlift_speed = 11\n')
    with pytest.raises(InputError, match="changed since the console started") as caught:
        params.propose(started, "motors.wheel_speed", "0.5")
    assert "safety.max_pitch_deg 15 → 30" in str(caught.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine.toml"]
    # the file as it was: the change is taken
    base.write_text('extends = "reference"\n')
    assert params.propose(started, "motors.wheel_speed", "0.5").new == 0.5


@pytest.mark.parametrize("taker", ["directory", "dangling link"])
def test_a_name_taken_by_no_regular_file_is_stepped_past_not_looped_on(
        config_home: Path, taker: str) -> None:
    # a name held by something not a regular file: the write went on trying
    # that same name forever, on the console's UI thread
    config_home.mkdir(parents=True)
    taken = config_home / "reference-params.toml"
    if taker == "directory":
        taken.mkdir()
    else:
        taken.symlink_to(config_home / "nowhere")
    started = load_config()
    params = Parameters(started)
    change = params.propose(started, "motors.wheel_speed", "0.5")
    written = params.write(change)
    assert written == config_home / "reference-params-1.toml"
    assert load_config(written).motors.wheel_speed == 0.5
