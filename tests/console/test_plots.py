"""Issue 35, "the console an operator trusts": plots of any signal (key v).
The picker lists every signal the console knows with its unit; those
picked are plotted over robot time in the graphs' place (textual-plotext);
the plotted values are the state's; a stale signal says STALE and is not
drawn on; a replay marks its errors, pauses and phase changes on a
timeline the operator jumps along (, and .)."""

from __future__ import annotations

import asyncio
import math
from typing import Any

from pilot import press, ready, until
from still_robot import ScriptedRobot, scripted_app
from textual.widgets import SelectionList

from stairbot.console.app import StairbotConsole
from stairbot.console.freshness import STALE_S
from stairbot.console.markers import markers_of, step
from stairbot.console.plot_picker import PlotPicker
from stairbot.console.replay_app import build_replay_app
from stairbot.console.signals import Samples, catalogue, fits, thin
from stairbot.console.widgets.plots import MIN_PERIOD_S
from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind
from stairbot.hardware import Imu, MotorId, MotorState, SensorId, SensorReading, Snapshot
from stairbot.recording.replay_source import ReplaySource, Tick

CONFIG = load_config()
PER_TURN = CONFIG.motors.lift_travel_per_turn


def snap(t: float, sfr: float = 0.3, mwf_speed: float = 0.0, mtf_turns: float = 0.0,
         pitch: float = 0.0, sfr_age: float = 0.0,
         health: dict[str, float] | None = None) -> Snapshot:
    sensors = {SensorId.SFR: SensorReading(sfr, age_s=sfr_age),
               SensorId.SFL: SensorReading(0.31), SensorId.SBR: SensorReading(0.04),
               SensorId.SBL: SensorReading(0.05)}
    motors = {m: MotorState(1.0) for m in MotorId}
    motors[MotorId.MWF] = MotorState(2.0, speed_tps=mwf_speed)
    motors[MotorId.MTF] = MotorState(mtf_turns)
    return Snapshot(t, sensors, motors, health or {}, imu=Imu(pitch, 1.5))




def read(app: StairbotConsole, robot: ScriptedRobot, *snaps: Snapshot) -> None:
    """The robot reads ``snaps``, one after the other (the idle poll reads the last)."""
    for s in snaps:
        robot.snap = s
        app.state.on_read(s)


async def pick(pilot: Any, app: StairbotConsole, *keys: str) -> None:
    """``v``, then Enter on each signal ``keys`` names, then ``v`` to plot them."""
    await press(pilot, "v")
    await until(pilot, lambda: isinstance(app.screen, PlotPicker), "the picker")
    picker = app.screen
    assert isinstance(picker, PlotPicker)
    listed = picker.query_one(SelectionList)
    await until(pilot, lambda: listed.has_focus, "the list has the keys")
    for key in keys:
        listed.highlighted = [listed.get_option_at_index(i).value
                              for i in range(listed.option_count)].index(key)
        was = key in picker.order
        await press(pilot, "enter")
        await until(pilot, lambda k=key, w=was: (k in picker.order) != w, f"{key} toggled")
    await press(pilot, "v")
    await until(pilot, lambda: not isinstance(app.screen, PlotPicker), "the picker closed")


def test_the_catalogue_holds_every_signal_with_its_unit() -> None:
    wired = snap(1.0, health={"frames_per_s": 200.0, "lost": 0.0, "crc_errors": 1.0,
                              "rtt_median_ms": 0.8})
    signals = {s.key: s for s in catalogue([wired], PER_TURN)}
    units = {k: s.unit for k, s in signals.items()}
    assert units["SFR"] == units["SBL"] == "m"
    assert units["pitch_deg"] == units["roll_deg"] == "°"
    assert units["MWF.speed"] == "turn/s" and units["MTB.turns"] == "turns"
    assert units["MTF.lift"] == "mm"
    assert units["link.frames_per_s"] == "frames/s" and units["link.rtt_median_ms"] == "ms"
    assert units["link.lost"] == units["link.errors"] == "count"
    assert units["SFR.age"] == "ms"
    assert "SSR" not in signals  # no side pair on this robot, none read
    assert not any(k.startswith("link.") for k in
                   (s.key for s in catalogue([snap(1.0)], PER_TURN)))  # a simulation's
    assert signals["MTF.lift"].value(snap(0, mtf_turns=2.0)) == 2.0 * PER_TURN * 1000
    assert signals["link.errors"].value(wired) == 1.0
    too_many = [signals[k] for k in ("SFR", "MTF.lift", "pitch_deg")]
    assert "at most 2 units" in fits(too_many) and "m, mm, °" in fits(too_many)
    assert fits(too_many[:2]) == ""


def test_samples_keep_one_reading_a_robot_time_and_start_afresh_when_it_goes_back() -> None:
    s = Samples(window_s=1.0)
    for i in range(100):
        s.add(snap(i * 0.02))
    s.add(snap(99 * 0.02, sfr=9.0))  # read again, the clock standing: nothing added
    kept = s.readings()
    assert len(kept) == 51 and kept[-1][1].sensors[SensorId.SFR].distance_m == 0.3
    s.add(snap(0.5))
    assert [t for t, _ in s.readings()] == [0.5]


def test_thinning_keeps_the_ends_and_each_buckets_lowest_and_highest() -> None:
    xs = [i * 0.01 for i in range(1001)]
    ys = [0.0] * 1001
    ys[500] = 7.0  # one reading's spike
    ys[501] = -3.0
    tx, ty = thin(xs, ys, 20)
    assert len(tx) <= 2 * 20 + 2 and tx == sorted(tx)
    assert (tx[0], ty[0]) == (0.0, 0.0) and (tx[-1], ty[-1]) == (xs[-1], 0.0)
    assert 7.0 in ty and -3.0 in ty and set(ty) == {0.0, 7.0, -3.0}
    assert thin(xs[:30], ys[:30], 20) == (xs[:30], ys[:30])  # few: as they are


def test_picked_signals_are_plotted_with_their_names_units_and_the_states_values() -> None:
    robot, ages = ScriptedRobot(snap(0.0)), [0.0]

    async def go() -> None:
        app = scripted_app(robot, ages)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            assert not app.plotting.panel.display  # 80x24: the picture
            await pick(pilot, app, "SFR", "MWF.speed", "MWB.speed")
            panel = app.plotting.panel
            await until(pilot, lambda: panel.display and not app.picture.display,
                        "the plot in the picture's place")
            assert not app.trends.display
            read(app, robot, *(snap(10 + i * 0.1, sfr=0.2 + i / 100, mwf_speed=i / 2)
                               for i in range(1, 6)))
            await until(pilot, lambda: len(panel.shown) == 3 and panel.shown[0].xs[-1] == 10.5,
                        "the legend")
            # the lines, within the throttle's period
            await until(pilot, lambda: panel.drawn[0][0][-1:] == [10.5], "the plot drawn")
            sfr, mwf, mwb = panel.shown
            state = app.state.view().snapshot
            assert state is not None
            assert sfr.ys[-1] == state.sensors[SensorId.SFR].distance_m == 0.25
            assert mwf.ys[-1] == state.motors[MotorId.MWF].speed_tps == 2.5
            assert mwb.ys[-1] == state.motors[MotorId.MWB].speed_tps == 0.0
            # what plotext was handed ends in the state's values too
            assert [(xs[-1], ys[-1]) for xs, ys in panel.drawn] == [
                (10.5, 0.25), (10.5, 2.5), (10.5, 0.0)]
            # every reading, not one a refresh
            assert sfr.xs == (0.0, *(10 + i * 0.1 for i in range(1, 6)))
            assert sfr.ys == (0.3, *(0.2 + i / 100 for i in range(1, 6)))
            legend = panel.plain_legend
            assert "SFR 0.250 m" in legend and "MWF speed 2.50 turn/s" in legend
            assert "MWB speed 0.00 turn/s" in legend
            assert "STALE" not in legend and not panel.has_class("-stale")
            # g: the picture back in their place, and g again the plot
            await press(pilot, "g")
            await until(pilot, lambda: app.picture.display and not panel.display,
                        "the picture back")
            await press(pilot, "g")
            await until(pilot, lambda: panel.display and not app.trends.display, "the plot")
            # none picked: the default graphs again
            await pick(pilot, app, "SFR", "MWF.speed", "MWB.speed")  # Enter drops each
            await until(pilot, lambda: app.trends.display and not panel.display,
                        "the graphs back")
    asyncio.run(go())


def test_the_picker_refuses_a_fifth_signal_or_a_third_unit_and_says_why() -> None:
    robot, ages = ScriptedRobot(snap(0.0)), [0.0]

    async def go() -> None:
        app = scripted_app(robot, ages)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "v")
            await until(pilot, lambda: isinstance(app.screen, PlotPicker), "the picker")
            picker = app.screen
            assert isinstance(picker, PlotPicker)
            listed = picker.query_one(SelectionList)
            prompts = [str(listed.get_option_at_index(i).prompt)
                       for i in range(listed.option_count)]
            assert any("SFR distance (m)" in p for p in prompts)
            assert any("MTB speed (turn/s)" in p for p in prompts)
            assert any("roll (°)" in p for p in prompts)
            for key in ("SFR", "SFL", "MWF.speed", "MTF.lift"):
                listed.select(key)
            await until(pilot, lambda: "not picked" in str(picker.why.render()),
                        "the third unit refused")
            assert picker.order == ["SFR", "SFL", "MWF.speed"]
            assert "MTF lift (mm) not picked: at most 2 units" in str(picker.why.render())
            for key in ("SBR", "SBL"):
                listed.select(key)
            await until(pilot, lambda: "at most 4 signals" in str(picker.why.render()),
                        "the fifth refused")
            assert picker.order == ["SFR", "SFL", "MWF.speed", "SBR"]
            await press(pilot, "escape")  # as it was: nothing plotted
            await until(pilot, lambda: not isinstance(app.screen, PlotPicker), "closed")
            assert app.plotting.picked == () and not app.plotting.panel.display
    asyncio.run(go())


def test_a_stale_signal_says_stale_and_is_not_drawn_on() -> None:
    robot, ages = ScriptedRobot(snap(0.0)), [0.0]

    async def go() -> None:
        app = scripted_app(robot, ages)
        async with app.run_test(size=(100, 40)) as pilot:
            await ready(pilot)
            await pick(pilot, app, "SFR", "SFL")
            panel = app.plotting.panel
            # SFR has not measured for longer than STALE_S: its value is old
            read(app, robot, *(snap(20 + i * 0.1) for i in range(1, 4)),
                 snap(20.4, sfr_age=STALE_S + 1))
            await until(pilot, lambda: panel.shown and panel.shown[0].xs[-1] == 20.4, "drawn")
            sfr, sfl = panel.shown
            assert sfr.stale and not sfl.stale
            assert "SFR 0.300 m STALE" in panel.plain_legend
            assert "SFL 0.310 m" in panel.plain_legend
            assert panel.plain_legend.count("STALE") == 1  # SFR's alone
            # no reading for longer than STALE_S: every signal STALE, the panel
            # dimmed, and nothing drawn past the last reading
            robot.silent = True
            points = len(panel.shown[1].xs)
            ages[0] += STALE_S + 1
            await until(pilot, lambda: panel.has_class("-stale"), "the plot dimmed")
            assert "STALE" in str(panel.border_title)
            assert panel.plain_legend.count("STALE") == 2
            assert all(s.stale for s in panel.shown)
            assert len(panel.shown[1].xs) == points and panel.shown[1].xs[-1] == 20.4
    asyncio.run(go())


def test_the_plot_redraws_at_most_once_a_period_and_says_stale_at_once() -> None:
    """Many readings a refresh: the legend follows each at once, the lines
    (plotext's costly build) at most once a throttle period of the panel's
    clock, and not at all while the panel is hidden; a stale signal says
    STALE in the legend at once, the throttle holding its lines."""
    robot, ages, clock = ScriptedRobot(snap(0.0)), [0.0], [1000.0]

    async def go() -> None:
        app = scripted_app(robot, ages)
        panel = app.plotting.panel
        panel.clock = lambda: clock[0]
        async with app.run_test(size=(100, 40)) as pilot:
            await ready(pilot)
            await pick(pilot, app, "SFR", "SFL")
            await until(pilot, lambda: panel.draws >= 1 and panel.plot.builds >= 1, "drawn")
            await pilot.pause(0.3)
            draws, builds = panel.draws, panel.plot.builds
            assert panel.period_s >= MIN_PERIOD_S
            for i in range(1, 301):  # 300 readings, 10 between two refreshes
                read(app, robot, snap(30 + i * 0.02, sfr=0.2 + i / 10000))
                if i % 10 == 0:
                    await pilot.pause(0.1)
            await until(pilot, lambda: "SFR 0.230 m" in panel.plain_legend,
                        "the legend at the last reading")
            await pilot.pause(0.3)
            assert panel.draws == draws  # the clock stood still: no lines drawn
            assert panel.plot.builds == builds
            # a stale sensor: STALE in the legend at once, the lines held back
            read(app, robot, snap(36.1, sfr_age=STALE_S + 1))
            await until(pilot, lambda: "SFR 0.300 m STALE" in panel.plain_legend, "STALE")
            assert panel.draws == draws and panel.plot.builds == builds
            # a period later, the lines held back are drawn, once
            clock[0] += panel.period_s
            await until(pilot, lambda: panel.draws == draws + 1, "the lines caught up")
            await until(pilot, lambda: panel.plot.builds == builds + 1, "plotext built them")
            assert panel.drawn[0][0][-1] == 36.1
            await pilot.pause(0.3)
            assert panel.draws == draws + 1  # nothing new: nothing drawn
            # hidden (g): nothing drawn, whatever comes and however long
            await press(pilot, "g")
            await until(pilot, lambda: not panel.display, "the plot hidden")
            for i in range(1, 51):
                read(app, robot, snap(40 + i * 0.02))
            clock[0] += 100.0
            await pilot.pause(0.5)
            assert panel.draws == draws + 1 and panel.plot.builds == builds + 1
    asyncio.run(go())


# -- replay ---------------------------------------------------------------------------

EVENTS = [
    Event(0.0, EventKind.PHASE, "calibrate", "calibrate", {"phase": "calibrate"}),
    Event(2.0, EventKind.INFO, "a measurement", "calibrate"),
    Event(3.0, EventKind.PHASE, "ascent", "ascent", {"phase": "ascent"}),
    Event(4.5, EventKind.PAUSE, "readings disagree", "ascent"),
    Event(5.0, EventKind.RESUME, "readings agree", "ascent"),
    Event(7.25, EventKind.ERROR, "SFR lost", "ascent"),
]


def source() -> ReplaySource:
    ticks = [Tick(i * 0.05, snap(i * 0.05, sfr=0.1 + i / 1000, mtf_turns=i / 10), None)
             for i in range(161)]  # 0 .. 8 s
    return ReplaySource("test.mcap", "mcap", ticks, list(EVENTS), True, CONFIG)


class Clock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def test_markers_are_the_recordings_errors_pauses_and_phases_at_their_times() -> None:
    markers = markers_of(EVENTS)
    assert [(m.time_s, m.kind) for m in markers] == [
        (0.0, "phase"), (3.0, "phase"), (4.5, "pause"), (7.25, "error")]
    assert step(markers, 3.0, +1) is markers[2]  # the one at the position: moves on
    assert step(markers, 3.0, -1) is markers[0]
    assert step(markers, 7.25, +1) is None


def test_replay_plots_the_recording_and_jumps_between_its_markers() -> None:
    async def go() -> None:
        clock = Clock()
        app = build_replay_app(source(), clock=clock, playing=False)
        async with app.run_test(size=(100, 40)) as pilot:
            await pilot.pause()
            assert app.plotting.markers == markers_of(EVENTS)
            await pick(pilot, app, "SFR", "MTF.lift")
            panel = app.plotting.panel
            await until(pilot, lambda: panel.display and panel.timeline.display, "the plot")
            assert "4 markers (keys , .) · here PHASE at 0.00 s: calibrate" in \
                panel.plain_timeline
            times = []
            for _ in range(3):
                await press(pilot, "full_stop")
                times.append(app.player.position)
                if len(times) == 1:
                    await until(pilot, lambda: "here PHASE at 3.00 s: ascent" in
                                panel.plain_timeline, "the timeline at the phase")
            assert times == [3.0, 4.5, 7.25]
            await until(pilot, lambda: panel.shown and panel.shown[0].xs[-1] == 7.25,
                        "drawn up to the error")
            sfr = panel.shown[0]
            assert sfr.ys[-1] == 0.1 + 145 / 1000  # the tick at 7.25 s, the recording's
            assert len(sfr.xs) == 146  # every tick from the start, whatever the speed
            assert "here ERROR at 7.25 s: SFR lost" in panel.plain_timeline
            assert " · next" not in panel.plain_timeline  # the last marker
            await press(pilot, "full_stop")  # none after: it stays, and says so
            assert app.player.position == 7.25
            await press(pilot, "comma")
            assert app.player.position == 4.5
            await until(pilot, lambda: panel.shown[0].xs[-1] == 4.5, "drawn back at 4.5 s")
            assert math.isclose(panel.shown[1].ys[-1], 9.0 * PER_TURN * 1000)
    asyncio.run(go())
