"""Issue 12, "runs you can look at": ``stairbot replay FILE`` (and ``stairbot
console --replay FILE``) plays a recording in the console.  A short run is
recorded here (sim://, calibration only, as fast as it goes), replayed on a
clock the test moves, and what the panels show is checked against the
recording as the ``mcap`` package's own reader reads it."""

from __future__ import annotations

import asyncio
import json
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader
from pilot import press, shown, until

from stairbot.cli import main
from stairbot.console.freshness import STALE_S
from stairbot.console.replay_app import ReplayConsole, build_replay_app
from stairbot.console.widgets.motors import NAMES as MOTOR_NAMES
from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind
from stairbot.hardware import BASE_SENSORS, MotorId, MotorState, SensorReading, Snapshot
from stairbot.inputs.scenario import load_scenario
from stairbot.recording import topics
from stairbot.recording.mcap_sink import McapRecord
from stairbot.recording.pose import DeadReckonedPose
from stairbot.recording.replay_load import load_replay
from stairbot.recording.replay_source import PART_GAP_S


class Clock:
    """The replay's clock: it moves when the test moves it."""

    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


@pytest.fixture(autouse=True)
def no_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    """A command that wrongly got as far as opening the screen fails here
    instead of waiting on a terminal the test does not have."""
    def opened(self: ReplayConsole, *args: Any, **kwargs: Any) -> None:
        raise AssertionError("the replay's screen opened")

    monkeypatch.setattr(ReplayConsole, "run", opened)


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A calibration on sim:// (about 13 s of robot time) as MCAP and as JSON lines."""
    d = tmp_path_factory.mktemp("replay")
    out = {"mcap": d / "cal.mcap", "jsonl": d / "cal.jsonl"}
    for path in out.values():
        assert main(["run", "-q", "--calibrate-only", "--record", str(path)]) == 0
    return out


def messages(path: Path, topic: str) -> list[dict[str, Any]]:
    """A JSON channel's messages, in order, read by the mcap package itself."""
    with path.open("rb") as f:
        return [json.loads(m.data) for _s, c, m in make_reader(f).iter_messages(topics=[topic])]


def at(msgs: list[dict[str, Any]], t: float) -> dict[str, Any]:
    """The last message at or before robot time ``t``."""
    return [m for m in msgs if m["time_s"] <= t][-1]


def replay_app(path: Path, clock: Clock, **kw: Any) -> ReplayConsole:
    return build_replay_app(load_replay(path), clock=clock, **kw)


def told(app: ReplayConsole) -> str:
    """The toasts on screen now, one a line."""
    return "\n".join(n.message for n in app._notifications)


def said(app: ReplayConsole) -> list[str]:
    return [event.message for _, event in app.state.view().events]


def run(go: Callable[[], Any]) -> None:
    asyncio.run(go())


def test_seeking_shows_the_recorded_sensors_motors_and_picture(recorded: dict[str, Path]) -> None:
    path = recorded["mcap"]
    sensors, motors = messages(path, topics.SENSORS), messages(path, topics.MOTORS)
    length = json.loads(recorded["jsonl"].read_text().splitlines()[-1])["time_s"]

    async def go() -> None:
        app = replay_app(path, Clock(), playing=False)
        async with app.run_test(size=(80, 24)) as pilot:
            await press(pilot, "right", "right", "right")  # 3 x 1 s
            await until(pilot, lambda: f"t = 3.0 s / {length:.1f} s" in app.banner.plain, "at 3 s")
            s, m = at(sensors, 3.0), at(motors, 3.0)
            assert s["time_s"] == 3.0
            screen = shown(app.sensors)
            for sensor in BASE_SENSORS:
                assert f"{sensor.value} {s[sensor.value]['distance_m']:5.3f} m" in screen
            assert "side" not in screen and "SSR" not in screen  # a robot without the pair
            lines = shown(app.motors).splitlines()
            for motor in MotorId:
                line = next(li for li in lines if f"{MOTOR_NAMES[motor]:<12} {motor.value}" in li)
                assert f"{m[motor.value]['turns']:7.1f}" in line, (motor, line)
            assert app.state.view().scene is not None  # the recorded pose, drawn
            assert "recorded on sim://" in str(app.picture.border_title)
            await press(pilot, "end")
            await until(pilot, lambda: f"t = {length:.1f} s / {length:.1f} s"
                        in app.banner.plain, "at the end")
            last = sensors[-1]
            assert f"SFR {last['SFR']['distance_m']:5.3f} m" in shown(app.sensors)
    run(go)


def test_banner_says_replay_and_the_file_and_no_robot_is_opened(
        recorded: dict[str, Path], monkeypatch: pytest.MonkeyPatch) -> None:
    opened: list[str] = []
    monkeypatch.setattr("stairbot.run.robots.open_robot", lambda url, *a, **k: opened.append(url))

    async def go() -> None:
        app = replay_app(recorded["mcap"], Clock())
        async with app.run_test(size=(80, 24)) as pilot:
            await until(pilot, lambda: "REPLAY" in app.banner.plain, "the banner")
            text = app.banner.plain
            assert text.startswith(" REPLAY ") and str(recorded["mcap"]) in text
            assert "recorded on sim://, default" in text
            assert not app.query("EStopButton")  # no E-STOP button pretending
            assert "no robot" in str(app.query_one("#replay-mark").render())
            assert "recorded simulation" in str(app.link.border_title)
            for key in "skcurox":
                await press(pilot, key)
            await pilot.pause(0.2)
            assert told(app).count("replay: no robot") == 7
            assert "cannot open" not in told(app)
            assert opened == [] and app.engine.session is None and app.engine.robot is None
            assert not app.engine.running
            assert app.state.view().status.robot == "replay"
    run(go)


def test_space_says_there_is_no_robot_and_the_replay_goes_on(recorded: dict[str, Path]) -> None:
    clock = Clock()

    async def go() -> None:
        app = replay_app(recorded["mcap"], clock)
        async with app.run_test(size=(80, 24)) as pilot:
            await press(pilot, "space")
            await until(pilot, lambda: "no robot to stop" in told(app), "the answer")
            assert app.player.playing  # not paused: no picture standing still as if stopped
            clock.t += 2.0
            app.advance()
            assert app.player.position == 2.0
            assert app.engine.session is None
            assert "E-STOP" not in app.banner.plain
    run(go)


def test_pause_stops_time_and_play_goes_on(recorded: dict[str, Path]) -> None:
    clock = Clock()

    async def go() -> None:
        app = replay_app(recorded["mcap"], clock)
        async with app.run_test(size=(80, 24)) as pilot:
            clock.t += 1.5
            app.advance()
            assert app.player.position == 1.5 and "▶ 1×" in app.banner.plain
            await press(pilot, "p")
            await until(pilot, lambda: not app.player.playing, "paused")
            assert "⏸ 1× · t = 1.5 s" in app.banner.plain
            clock.t += 5.0
            app.advance()
            assert app.player.position == 1.5  # paused: the clock moved, the replay did not
            await press(pilot, "p")
            await until(pilot, lambda: app.player.playing, "playing again")
            clock.t += 0.5
            app.advance()
            assert app.player.position == 2.0
            clock.t += 60.0  # past the end: it stops there
            app.advance()
            assert app.player.position == app.player.end_s and not app.player.playing
            assert "■" in app.banner.plain
            await press(pilot, "p")  # at the end: from the start again
            await until(pilot, lambda: app.player.playing, "playing from the start")
            assert app.player.position == app.player.start_s
    run(go)


def test_speed_changes_how_fast_the_recording_goes(recorded: dict[str, Path]) -> None:
    clock = Clock()

    async def go() -> None:
        app = replay_app(recorded["mcap"], clock)
        async with app.run_test(size=(80, 24)) as pilot:
            await press(pilot, "plus")
            await until(pilot, lambda: app.player.speed == 2.0, "twice as fast")
            assert "▶ 2×" in app.banner.plain
            assert "replay 2×" in shown(app.link)
            clock.t += 1.0
            app.advance()
            assert app.player.position == 2.0
            await press(pilot, "minus", "minus", "minus")
            await until(pilot, lambda: app.player.speed == 0.25, "a quarter as fast")
            assert "0.25×" in app.banner.plain
            clock.t += 2.0
            app.advance()
            assert app.player.position == 2.5
            for _ in range(10):
                await press(pilot, "plus")
            await until(pilot, lambda: app.player.speed == 50.0, "the fastest")
            await pilot.pause(0.2)  # every plus handled: still the fastest, not beyond
            assert app.player.speed == 50.0
    run(go)


def test_seek_keys_go_to_the_right_time_and_back_replays_the_events(
        recorded: dict[str, Path]) -> None:
    events = [json.loads(line) for line in recorded["jsonl"].read_text().splitlines()]

    async def go() -> None:
        app = replay_app(recorded["mcap"], Clock(), playing=False)
        async with app.run_test(size=(100, 40)) as pilot:
            await press(pilot, "end")
            end = app.player.end_s
            assert end == events[-1]["time_s"] > 6.0  # the recording's last event
            await until(pilot, lambda: app.player.position == end, "at the end")
            await until(pilot, lambda: len(app.log_panel._kept) == len(events), "every event")
            assert said(app) == [e["message"] for e in events]  # the whole list, in order
            await press(pilot, "left")
            await until(pilot, lambda: app.player.position == pytest.approx(end - 1), "1 s back")
            await press(pilot, "shift+left")
            await until(pilot, lambda: app.player.position == pytest.approx(end - 6), "5 s back")
            await press(pilot, "right_square_bracket")
            await until(pilot, lambda: app.player.position == pytest.approx(end - 1),
                        "5 s on")
            await press(pilot, "home")
            await until(pilot, lambda: app.player.position == 0.0, "at the start")
            at_start = [e["message"] for e in events if e["time_s"] <= 0.0]
            assert said(app) == at_start  # sought back: the list as it was at 0 s
            await until(pilot, lambda: len(app.log_panel._kept) == len(at_start),
                        "the shown list emptied and played again")
            await press(pilot, "left")
            assert app.player.position == 0.0  # not before the start
            await press(pilot, "right", "right")
            await until(pilot, lambda: app.player.position == 2.0, "at 2 s")
            assert said(app) == [e["message"] for e in events if e["time_s"] <= 2.0]
            phases = [e for e in events if e["kind"] == "phase" and e["time_s"] <= 2.0]
            assert app.state.view().phase == phases[-1]["phase"]
    run(go)


def test_t_in_a_replay_shows_no_top_view_and_says_why(recorded: dict[str, Path]) -> None:
    """The recording holds the side view's pose in the frame the simulation was
    in, not which frame: nothing is drawn from above rather than something wrong."""
    async def go() -> None:
        app = replay_app(recorded["mcap"], Clock(), playing=False)
        async with app.run_test(size=(80, 24)) as pilot:
            await press(pilot, "right", "t")
            await until(pilot, lambda: app.top_view.display, "the top view")
            assert not app.picture.display
            text = app.top_view.render().plain
            assert not any(0x2800 < ord(ch) < 0x2900 for ch in text)
            assert "a recording holds no pose seen from above" in " ".join(text.split())
    run(go)


def test_graphs_in_a_replay_draw_the_recorded_window(recorded: dict[str, Path]) -> None:
    sensors = messages(recorded["mcap"], topics.SENSORS)

    async def go() -> None:
        app = replay_app(recorded["mcap"], Clock(), playing=False)
        async with app.run_test(size=(100, 40)) as pilot:
            await press(pilot, "right_square_bracket")  # 5 s
            expected = [m["SFR"]["distance_m"] for m in sensors if m["time_s"] <= 5.0]
            await until(pilot, lambda: list(app.trends.lines["SFR"].data or []) == expected,
                        "the first 5 s of SFR drawn")
            assert app.trends.plain["SFR"].startswith(f"front R  {expected[-1]:.3f} | ")
    run(go)


def test_a_json_lines_record_plays_its_events_and_says_it_has_no_values(
        recorded: dict[str, Path]) -> None:
    events = [json.loads(line) for line in recorded["jsonl"].read_text().splitlines()]
    clock = Clock()

    async def go() -> None:
        app = replay_app(recorded["jsonl"], clock)
        async with app.run_test(size=(80, 24)) as pilot:
            await until(pilot, lambda: "REPLAY" in app.banner.plain, "the banner")
            assert "JSON lines: events only, no sensor or motor values" in app.banner.plain
            assert "never read" in str(app.sensors.border_title)
            assert "never read" in str(app.motors.border_title)
            assert app.picture_note().startswith("no picture")
            clock.t += 5.0
            app.advance()
            assert said(app) == [e["message"] for e in events if e["time_s"] <= 5.0]
            phases = [e for e in events if e["kind"] == "phase" and e["time_s"] <= 5.0]
            assert app.state.view().phase == phases[-1]["phase"]
            assert app.state.view().flow == "calibration"
    run(go)


def test_a_recording_cut_short_plays_what_it_holds(recorded: dict[str, Path],
                                                   tmp_path: Path) -> None:
    """A run killed outright leaves no summary and may end inside a chunk."""
    cut = tmp_path / "cut.mcap"
    data = recorded["mcap"].read_bytes()
    cut.write_bytes(data[: len(data) * 2 // 3])
    source = load_replay(cut)
    assert not source.complete and 0 < len(source.ticks) < 668

    async def go() -> None:
        app = build_replay_app(source, clock=Clock(), playing=False)
        async with app.run_test(size=(80, 24)) as pilot:
            await press(pilot, "end")
            await until(pilot, lambda: app.player.position == source.end_s, "at the end")
            assert f"cut short: the file ends at {source.end_s:.1f} s" in app.banner.plain
            snap = app.state.view().snapshot
            assert snap is not None and snap.time_s == max(
                t.time_s for t in source.ticks if t.snapshot is not None)
    run(go)


def _gap_recording(path: Path) -> None:
    """Ticks from 0 to 1 s, none until 5.5 s, then to 6 s (a console idle between runs)."""
    record = McapRecord(path, load_config(None))
    try:
        for i in [*range(51), *range(275, 301)]:
            t = i * 0.02
            snap = Snapshot(t, {s: SensorReading(0.3 + i / 1000) for s in BASE_SENSORS},
                            {m: MotorState(float(i)) for m in MotorId})
            record.tick(snap, None)
    finally:
        record.close()


def test_ages_are_the_recordings_a_gap_shows_stale(tmp_path: Path) -> None:
    path = tmp_path / "gap.mcap"
    _gap_recording(path)

    async def go() -> None:
        app = replay_app(path, Clock(), playing=False)
        async with app.run_test(size=(80, 24)) as pilot:
            await press(pilot, "right_square_bracket")  # 0 -> 5 s at once: the last
            # tick at 1 s, 4 s before (read into the state when the position was 5 s)
            await until(pilot, lambda: "STALE" in str(app.sensors.border_title), "stale")
            assert "STALE 4.0 s" in str(app.sensors.border_title)
            assert app.sensors.has_class("-stale") and app.motors.has_class("-stale")
            assert 4.0 > STALE_S
            await press(pilot, "right")  # 6 s: ticks again
            await until(pilot, lambda: "0.0 s ago" in str(app.sensors.border_title), "fresh")
            assert not app.sensors.has_class("-stale")
    run(go)


def _two_robots(path: Path) -> None:
    """A console's recording across a reset: two robots, each clock from 0
    (ticks 0..1 s, SFR 0.3 m and up; then 0..1 s again, SFR 0.5 m and up)."""
    config, scenario = load_config(None), load_scenario(None)
    record = McapRecord(path, config)
    try:
        for base in (0.3, 0.5):
            record.watch(DeadReckonedPose(config, scenario), scenario, "sim://")
            record.write(Event(0.0, EventKind.INFO, f"robot at {base}"))
            for i in range(51):
                snap = Snapshot(i * 0.02, {s: SensorReading(base + i / 1000) for s in BASE_SENSORS},
                                {m: MotorState(float(i)) for m in MotorId})
                record.tick(snap, None)
    finally:
        record.close()


def test_a_recording_of_two_robots_plays_one_after_the_other(tmp_path: Path) -> None:
    """Finding: the second robot's ticks, at the same clock times as the
    first's, were merged into them."""
    path = tmp_path / "two.mcap"
    _two_robots(path)
    source = load_replay(path)
    assert len(source.parts) == 2 and len(source.ticks) == 102
    assert [t.time_s for t in source.ticks] == sorted(t.time_s for t in source.ticks)
    assert source.end_s == pytest.approx(2.0 + PART_GAP_S)

    async def go() -> None:
        app = build_replay_app(source, clock=Clock(), playing=False)
        async with app.run_test(size=(100, 40)) as pilot:
            await press(pilot, "right")  # 1 s: the first robot's last tick
            await until(pilot, lambda: "robot 1 of 2 (its clock 1.0 s)" in app.banner.plain,
                        "the first robot")
            assert "SFR 0.350 m" in shown(app.sensors)
            app.player.seek(source.parts[1].start_s + 0.5)  # the second robot at 0.5 s
            app.show_player()
            assert "robot 2 of 2 (its clock 0.5 s)" in app.banner.plain
            await until(pilot, lambda: "SFR 0.525 m" in shown(app.sensors), "the second robot")
            snap = app.state.view().snapshot
            assert snap is not None and snap.time_s == pytest.approx(0.5)
            # the graphs start again with the second robot's clock
            await until(pilot, lambda: len(app.trends.lines["SFR"].data or []) == 26,
                        "the second robot's readings alone")
            assert said(app) == ["robot at 0.3", "robot at 0.5"]
    run(go)


def test_messages_that_do_not_read_are_skipped_and_said(tmp_path: Path) -> None:
    """A damaged message costs its tick, not the replay, and the banner says so."""
    from mcap.writer import Writer

    path = tmp_path / "damaged.mcap"
    good = {"time_s": 0.0, "SFR": {"distance_m": 0.3, "status": "ok", "age_s": 0.0}}
    with path.open("wb") as f:
        writer = Writer(f)
        writer.start()
        writer.add_metadata("stairbot", {"time_origin_ns": "0"})
        schema = writer.register_schema(name="stairbot.Sensors", encoding="jsonschema",
                                        data=b"{}")
        channel = writer.register_channel(topic=topics.SENSORS, message_encoding="json",
                                          schema_id=schema)
        bad_status = {**good, "time_s": 0.02, "SFR": {**good["SFR"], "status": "weird"}}
        for i, data in enumerate((json.dumps(good).encode(), b"{not json",
                                  json.dumps(bad_status).encode())):
            writer.add_message(channel, log_time=i * 20_000_000, data=data,
                               publish_time=i * 20_000_000)
        writer.finish()
    source = load_replay(path)
    assert len(source.ticks) == 1
    assert source.notes == ["1 unreadable message on /robot/sensors skipped",
                            "1 unreadable tick skipped", "the recording holds no robot config"]

    async def go() -> None:
        app = build_replay_app(source, clock=Clock(), playing=False)
        async with app.run_test(size=(80, 24)) as pilot:
            await until(pilot, lambda: "REPLAY" in app.banner.plain, "the banner")
            assert "1 unreadable message on /robot/sensors skipped" in app.banner.plain
            assert "drawn with <default default_robot.toml>" in app.banner.plain
            assert "SFR 0.300 m" in shown(app.sensors)
    run(go)


# -- bad input: one line, exit 2 (1 for a read the disk fails) ------------------------


def _foreign_mcap(path: Path) -> None:
    from mcap.writer import Writer

    with path.open("wb") as f:
        writer = Writer(f)
        writer.start()
        writer.finish()


BAD: dict[str, tuple[str, Any, str]] = {
    "missing": ("missing.mcap", None, "cannot read a recording: No such file or directory"),
    "directory": ("dir.mcap", "dir", "cannot read a recording: a directory"),
    "not-mcap": ("text.mcap", b"hello\n", "named .mcap but not an MCAP file"),
    "unknown-extension": ("run.csv", b"a,b\n", "not a recording's name (suffix '.csv')"),
    "no-extension": ("run", b"{}\n", "not a recording's name (no suffix)"),
    "empty": ("empty.mcap", b"", "empty; allowed: an MCAP or JSON-lines recording"),
    "foreign-mcap": ("foreign.mcap", _foreign_mcap, "an MCAP file, but not a stairbot recording"),
    "jsonl-not-json": ("x.jsonl", b"not json\nat all\n", "line 1: not JSON"),
    "mcap-named-jsonl": ("run.jsonl", "mcap", "an MCAP file named as JSON lines"),
}


@pytest.mark.parametrize("case", sorted(BAD))
@pytest.mark.parametrize("command", [["replay"], ["console", "--replay"]])
def test_bad_input_is_one_line_and_exit_2(case: str, command: list[str], tmp_path: Path,
                                          recorded: dict[str, Path],
                                          capsys: pytest.CaptureFixture[str]) -> None:
    name, content, expected = BAD[case]
    path = tmp_path / name
    if content == "dir":
        path.mkdir()
    elif content == "mcap":
        path.write_bytes(recorded["mcap"].read_bytes())
    elif isinstance(content, bytes):
        path.write_bytes(content)
    elif content is not None:
        content(path)
    assert main([*command, str(path)]) == 2
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err and len(lines) == 1, err
    assert lines[0].startswith(f"stairbot: error: {path}: ") and expected in lines[0], lines[0]


def test_a_read_the_disk_fails_is_one_line_and_exit_1(
        recorded: dict[str, Path], recording_read_fails: None,
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["replay", str(recorded["mcap"])]) == 1
    err = capsys.readouterr().err
    assert err == (f"stairbot: error: {recorded['mcap']}: cannot read the recording: "
                   "Input/output error\n")


def test_console_replay_refuses_the_options_of_a_robot(
        recorded: dict[str, Path], capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    played: list[tuple[str, float]] = []
    monkeypatch.setattr("stairbot.console.replay_cli.replay",
                        lambda path, speed: played.append((path, speed)) or 0)
    assert main(["console", "--replay", str(recorded["mcap"]), "--speed", "10x"]) == 0
    assert played == [(str(recorded["mcap"]), 10.0)]  # without them: played, at 10x
    assert main(["console", "--replay", str(recorded["mcap"]), "--robot", "serial:///dev/x",
                 "--record", "x.mcap"]) == 2
    err = capsys.readouterr().err
    assert err == ("stairbot: error: --replay: plays a recording: no robot is opened, so "
                   "--robot, --record cannot be given with it\n")


@pytest.mark.parametrize("argv", [["replay", "--help"], ["--help"]])
def test_help_answers_and_lists_replay(argv: list[str],
                                       capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 0
    out = capsys.readouterr().out
    assert ("usage: stairbot replay" in out and "FILE.mcap" in out) if argv[0] == "replay" \
        else "    replay " in out


def test_without_the_mcap_reader_one_line_names_the_extra(recorded: dict[str, Path]) -> None:
    probe = ("import sys; sys.modules['mcap'] = None\n"
             "from stairbot.cli import main; sys.exit(main(sys.argv[1:]))")
    proc = subprocess.run([sys.executable, "-c", probe, "replay", str(recorded["mcap"])],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr == ("stairbot: error: stairbot replay: needs mcap to read MCAP, which "
                           "is not installed: pip install 'stairbot[replay]'\n")


def test_a_json_lines_replay_shows_no_value_as_an_error_console_defect_8(
        recorded: dict[str, Path]) -> None:
    """Findings: graphs of a record with no sensor values read "ERROR" for
    every sensor; the close-in's phase line said "(start) (start)"."""
    clock = Clock()

    async def go() -> None:
        app = replay_app(recorded["jsonl"], clock)
        async with app.run_test(size=(120, 40)) as pilot:
            await until(pilot, lambda: "REPLAY" in app.banner.plain, "the banner")
            clock.t += 5.0
            app.advance()
            await until(pilot, lambda: bool(app.trends.plain), "the graphs drawn")
            for name in ("SFR", "SFL", "SBR", "SBL"):
                assert app.trends.plain[name].endswith("—"), app.trends.plain[name]
            assert not any("ERROR" in line for line in app.trends.plain.values())
            assert not any("(start) (start)" in message for message in said(app))
            assert any("close in to square_range_m (start)" in m for m in said(app))
    run(go)
