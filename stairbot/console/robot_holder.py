"""What the console holds open between runs: the robot, opened by URL and
read while idle, its paced clock, and the record the console writes.

Every call to the robot and the clock happens under one lock
(:attr:`RobotHolder.robot_lock`), so the idle reads here, the run thread
(:class:`~stairbot.console.engine.ConsoleEngine`) and the emergency stop
from the UI thread never talk to the robot at once.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable
from dataclasses import replace
from typing import TYPE_CHECKING
from urllib.parse import urlsplit

from stairbot.console.climb_gate import MidClimb, from_journal
from stairbot.console.freshness import POLL_PERIOD_S, STILL_TPS
from stairbot.console.limp_gate import LimpOffer
from stairbot.console.state import LiveState
from stairbot.console.watch import PacedClock, WatchedRobot, watch
from stairbot.errors import InputError, LatchedError, OutputError, StairbotError
from stairbot.events import Event, EventKind
from stairbot.hardware import HasScene, HasTruth, ReportsEvents
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, load_scenario
from stairbot.recording.record import JsonLinesRecord, RecordsTicks, is_mcap
from stairbot.run.journaled import default_path
from stairbot.run.paths import unused_path
from stairbot.run.robots import RobotOptions, RobotSession
from stairbot.views.side_view import SceneView, scene_view, stairs_from_scenario
from stairbot.views.top_view import TopPlan, TopPose, plan_of, top_pose

if TYPE_CHECKING:  # the Foxglove SDK loads only for an MCAP record or --foxglove
    from stairbot.recording.live import LiveServer
    from stairbot.recording.mcap_sink import McapRecord

LATCH_HINT = "EMERGENCY STOP latched — c clears it (after you look at the robot)"
NO_ROBOT_STOPPED = ("no robot connected: nothing was stopped — the console's stop is latched "
                    "for any robot opened until c clears it")

SPEEDS: dict[str, float | None] = {"1x": 1.0, "10x": 10.0, "max": None}
"""Simulation speeds the operator can pick: sim seconds per wall second."""
IDLE_CATCH_UP_S = 2.0
"""The most robot time one idle read of a simulation passes (a console
that was busy or asleep does not simulate all it missed)."""

OpenFn = Callable[[str, RobotConfig, Scenario, RobotOptions], RobotSession]


def default_open(url: str, config: RobotConfig, scenario: Scenario,
                 options: RobotOptions) -> RobotSession:
    """The robot at ``url`` on ``scenario``'s world (:func:`stairbot.run.robots.open_robot`)."""
    from stairbot.run.robots import open_robot

    return open_robot(url, config, replace(options, world=scenario))


def boards_words(identity: dict[str, dict[str, int]] | None) -> str:
    """``motor #4660 · sensor #22136``: each board and its serial number
    ("": no boards, a simulation)."""
    if not identity:
        return ""
    return " · ".join(f"{name} #{ident.get('serial', '?')}"
                      for name, ident in sorted(identity.items()))


class RobotHolder:
    """The robot the console has open (none at first), its clock and the
    record; :class:`~stairbot.console.engine.ConsoleEngine` runs the
    program on them."""

    def __init__(self, state: LiveState, config: RobotConfig, *,
                 open_fn: OpenFn = default_open,
                 wall: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        self.state = state
        self.config = config
        """The config the runs use (the parameters screen, ``i``, may change
        its runtime-safe values between runs: console/param_edit.py)."""
        self.world_config = config
        """The config robots are opened with: the simulation's world (the
        robot's bodies, sensors and motors) is built from it and stays the
        same whatever the runs' config changes."""
        self._open_fn = open_fn
        self._wall, self._sleep = wall, sleep
        self._lock = threading.RLock()
        self.session: RobotSession | None = None
        self.robot: WatchedRobot | None = None
        self.clock: PacedClock | None = None
        self.scenario: Scenario | None = None
        self.recorder: JsonLinesRecord | McapRecord | None = None
        self.live: LiveServer | None = None
        """``--foxglove``: the live server, which an MCAP record started here
        shares (its channels), else fed here; the console's owner stops it."""
        self._running = threading.Event()
        self._speed = "max"
        self._poller: threading.Thread | None = None
        self._closing = threading.Event()
        self._poll_fault: str | None = None  # why the last idle read failed
        self._idle_at: float | None = None  # wall time of the last idle read of a simulation
        self._opening = False
        self.mid_climb: MidClimb | None = None
        """The robot may stand part way up (stairbot.console.climb_gate): no
        fresh start until the operator resumes or says it is back at the start."""
        self.latched_boards: tuple[str, str | None, str] | None = None
        """(url, scenario, why) of boards refused for the latch they hold."""
        self.limp_offer: LimpOffer | None = None
        """The last run's degraded stop, which the robot can limp home from once
        the operator consents (stairbot.console.limp_gate); None: none."""

    # -- robot -----------------------------------------------------------------
    @property
    def robot_lock(self) -> threading.RLock:
        """Held around every call to the robot and the clock (take it to look at
        the simulation from another thread)."""
        return self._lock

    @property
    def running(self) -> bool:
        return self._running.is_set()

    @property
    def in_process(self) -> bool:
        """The simulation runs here (sim://): the console draws it and sets its speed."""
        return self.session is not None and self.session.sim is not None

    @property
    def latched(self) -> bool:
        """The console's emergency stop latch: set by the operator or by a run
        that ended on an error; it outlives the robot (a reset, another URL)
        and only :meth:`~stairbot.console.engine.ConsoleEngine.clear_estop`
        clears it."""
        return self.state.view().status.estopped

    def open(self, url: str, scenario_path: str | None, *, clear_latches: bool = False) -> None:
        """Open the robot at ``url`` on the scenario (None: the default stairs),
        closing the previous one.  Opening never clears a latch: the
        console's own carries over to the new robot (its ``estop()`` is
        called at once), and boards that hold one are refused (LatchedError,
        naming ``c`` and ``stairbot clear``; :attr:`latched_boards` remembers
        them) -- unless ``clear_latches``: the operator pressed ``c`` and
        confirmed, and the boards' latches and the console's are cleared.
        Raises InputError (bad URL or scenario) or StairbotError (the robot
        cannot be opened); the old robot stays closed."""
        if self.running:
            raise InputError(url, None, "a run is going on; stop it first")
        scenario = load_scenario(scenario_path)
        self._opening = True
        try:
            self._open(url, scenario, scenario_path, clear_latches)
        finally:
            self._opening = False

    def _open(self, url: str, scenario: Scenario, scenario_path: str | None,
              clear_latches: bool) -> None:
        self.close()
        self._poll_fault = None
        self.limp_offer = None  # the program it belongs to ran on the robot closed
        # the robot being opened, before it answers: a refused one is not taken
        # for a simulation, nor shown with the closed one's readings
        simulated = urlsplit(url).scheme == "sim"
        self.state.set_robot(url, scenario.name, simulated, wired=not simulated)
        self.state.set_status(robot="connecting", message=f"opening {url}", severity="info")
        try:
            session = self._open_fn(url, self.world_config, scenario,
                                    RobotOptions(allow_latched=clear_latches))
        except LatchedError as exc:
            message = f"{exc}; or press c here once you have looked at the robot"
            self.latched_boards = (url, scenario_path, message)
            raise LatchedError(message) from None
        self.latched_boards = None
        if clear_latches:
            try:
                session.robot.clear()  # the boards' latches, as `stairbot clear` does
            except BaseException:
                with contextlib.suppress(Exception):
                    session.close()
                raise
            self.state.set_status(estopped=False, latch="")
            self._sink(Event(self._now(), EventKind.INFO,
                             "latches cleared by the operator (confirmed)"))
        self.session, self.scenario = session, scenario
        sim = session.sim
        scene_fn: Callable[[], SceneView] | None = None
        if isinstance(sim, HasScene):
            def scene_fn() -> SceneView:
                return scene_view(sim.scene())
        # the top view: a simulation that tells its truth tells its pose seen from above
        top_fn: Callable[[], TopPose | None] | None = None
        plan: TopPlan | None = None
        if isinstance(sim, HasTruth):
            truthful = sim  # bound for the closure, narrowed

            def top_fn() -> TopPose | None:
                return top_pose(truthful.truth())
            plan = plan_of(scenario)
        if isinstance(session.robot, ReportsEvents):  # LINK events: the log and the record
            session.robot.attach_sink(self._sink)
        self.robot = watch(session.robot, self.state, self._lock, scene_fn, self._wall, top_fn)
        if self.latched:  # the latch outlives the robot it was pressed on
            self.robot.estop()
        self.clock = PacedClock(session.clock, self._lock, self._wall, self._sleep)
        self.clock.set_scale(SPEEDS[self._speed] if sim is not None else None)
        stairs = stairs_from_scenario(scenario, self.config.LENGTH_OF_A_ROBOT)
        self.state.set_robot(url, scenario.name, session.simulated, stairs, wired=sim is None,
                             plan=plan)
        self._recording_safely(self._watch_recording)
        try:
            self.robot.read()  # first readings and picture, before any motion
        except StairbotError as exc:
            self.state.set_status(robot="fault", message=f"cannot read the robot: {exc}",
                                  severity="error")
            return
        self.robot.refresh_scene()
        # boards: their journal says whether an earlier host left them mid-climb
        identity = self.robot.identity()
        self.mid_climb = None if sim is not None else from_journal(default_path(url, identity),
                                                                   identity)
        self.state.set_boards(boards_words(identity))
        latched = self.latched
        self.state.set_status(robot="ready", paused=False,
                              message=LATCH_HINT if latched else "",
                              severity="error" if latched else "info")

    # -- idle polling --------------------------------------------------------------
    def start_polling(self, period_s: float = POLL_PERIOD_S) -> None:
        """Read the robot every ``period_s`` while no run goes on (a daemon
        thread, until
        :meth:`~stairbot.console.engine.ConsoleEngine.shutdown`): its sensors and link stay live on
        the screen, and a link that dies while idle shows as a FAULT."""
        if self._poller is not None:
            return
        self._poller = threading.Thread(target=self._poll_loop, args=(period_s,),
                                        name="console idle poll", daemon=True)
        self._poller.start()

    def _poll_loop(self, period_s: float) -> None:
        while not self._closing.wait(period_s):
            self.poll()

    def poll(self) -> None:
        """One idle read (nothing while a run goes on: the run reads every
        tick).  A read that fails makes the state FAULT with the driver's
        reason, once; one that works again after that makes it READY."""
        robot = self.robot
        if robot is None or self.running or self._opening:
            self._idle_at = None
            return
        try:
            self._pass_idle_time()
            robot.read()
        except Exception as exc:  # noqa: BLE001 - a failing read is news, not a crash
            if self.running or robot is not self.robot:
                return  # a run or another robot took over meanwhile
            # the driver's message names the port; the banner's strip, the URL
            why = f"no reading from the robot: {exc}"
            if why != self._poll_fault:
                self._poll_fault = why
                self.state.set_status(robot="fault", severity="error", message=why)
                self.state.note(why, "error")
            return
        if self._poll_fault is not None and robot is self.robot and not self.running:
            self._poll_fault = None
            self.state.set_status(robot="ready", severity="warning",
                                  message="the robot answers again")
            self.state.note("the robot answers again", "warning")

    def _pass_idle_time(self) -> None:
        """While a simulation's motors still read as moving (a run stopped
        mid-motion), its time goes on with no run, as a robot's would: its
        physics runs, every motor stopped and the lifts holding, for the wall
        time since the last idle read at the chosen speed (1x at max), at most
        IDLE_CATCH_UP_S.  So an idle read says what the robot does now -- its
        motors still, not their speeds when the run stopped.  A simulation at
        rest stays as it is (a run started from it is the headless run's)."""
        clock = self.clock
        snap = self.state.snapshot
        if clock is None or not self.in_process or snap is None or all(
                abs(m.speed_tps) < STILL_TPS for m in snap.motors.values()):
            self._idle_at = None
            return
        now = self._wall()
        last, self._idle_at = self._idle_at, now
        if last is None:
            return
        tick = self.config.algorithm.tick
        due = min((now - last) * (SPEEDS[self._speed] or 1.0), IDLE_CATCH_UP_S)
        for _ in range(int(due / tick + 1e-9)):
            clock.idle(tick)

    def close(self) -> None:
        """Stop and release the robot (never raises)."""
        if self.robot is not None:
            with contextlib.suppress(Exception):  # closing must not fail the console
                self.robot.close()
        self.session = self.robot = self.clock = None

    def set_speed(self, speed: str) -> None:
        self._speed = speed
        if self.clock is not None and self.in_process:
            self.clock.set_scale(SPEEDS[speed])
        self.state.set_speed(speed)

    # -- events and the record ---------------------------------------------------
    def _sink(self, event: Event) -> None:
        """The run's events (and the engine's own): the live state, the record.
        A record the disk refuses raises OutputError, which ends a run as it
        does ``stairbot run``'s."""
        self.state.on_event(event)
        if self.recorder is not None:
            self.recorder.write(event)
        feed = self.live_feed()
        if feed is not None:
            feed.write(event)

    def _say(self, event: Event) -> None:
        """An event from the UI thread: a refused record write stops the
        recording (and says so) rather than reach the key that pressed it."""
        self._recording_safely(lambda: self._sink(event))

    def _recording_safely(self, write: Callable[[], None]) -> None:
        try:
            write()
        except (OutputError, OSError) as exc:
            self.state.set_status(severity="error", message=f"recording stopped: {exc}")
            self.stop_recording()

    def _watch_recording(self) -> None:
        """Tell an MCAP record which robot its ticks come from (and where it
        stands: the simulation's pose, or a dead-reckoned one)."""
        recorder, session, scenario = self.recorder, self.session, self.scenario
        watchers = [r for r in (recorder, self.live_feed()) if isinstance(r, RecordsTicks)]
        if watchers and session is not None and scenario is not None:
            from stairbot.recording.pose import pose_source

            pose = pose_source(session.sim, self.config, scenario)
            for watcher in watchers:
                watcher.watch(pose, scenario, session.url)

    def live_feed(self) -> LiveServer | None:
        """The live server when the console logs to it itself: not while an
        MCAP record on its channels does (every message to both)."""
        return self.live.feed(self.recorder) if self.live is not None else None

    def start_recording(self, path: str) -> str:
        """Record from now on to ``path``, or, when a file is there already,
        beside it under a name not taken (``name-1.jsonl``: a recording is
        never overwritten); returns the path written to.  A name ending .mcap
        records every tick and event as MCAP (as ``stairbot run --record
        FILE.mcap``), any other the events as JSON lines.  Raises InputError
        (the file cannot be opened, or an MCAP file's start cannot be
        written)."""
        self.stop_recording()
        try:
            chosen = unused_path(path)
        except FileExistsError as exc:
            raise InputError(path, None, f"cannot write the record: {exc}") from None
        if is_mcap(chosen):
            from stairbot.recording.mcap_sink import McapRecord

            try:
                self.recorder = McapRecord(chosen, self.config, channels=None if self.live is None
                                           else self.live.channels)
                self._watch_recording()
            except OutputError as exc:
                self.stop_recording()
                raise InputError(exc.path, None, f"cannot write {exc.what}: "
                                 f"{exc.problem}") from None
        else:
            self.recorder = JsonLinesRecord(chosen)  # whole lines; a full disk: OutputError
        self.state.set_recording(chosen)
        return chosen

    def stop_recording(self) -> None:
        """Stop recording (an MCAP file is finished: its summary written).
        Never raises: a file the disk refused to finish keeps what it had."""
        recorder, self.recorder = self.recorder, None
        if recorder is not None:
            try:
                recorder.close()
            except (OutputError, OSError) as exc:
                self.state.set_status(severity="error", message=f"recording stopped: {exc}")
        self.state.set_recording(None)

    def _now(self) -> float:
        snap = self.state.snapshot
        return snap.time_s if snap is not None else 0.0
