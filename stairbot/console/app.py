"""The operator console: one function, :func:`build_app`, builds it (the tests
build it the same way).

The run goes on a worker thread (the runner's loop); the screen redraws ten
times a second from a copy of the live state, however fast or slow the control
loop ticks.  The emergency stop key is taken in ``on_event`` before any
screen or widget sees it, so it works on every screen, even over a text
prompt (which therefore cannot take a space: one key that always stops beats
a second key to remember when it matters); the binding shows it in the footer.
"""

from __future__ import annotations

import contextlib
import signal
import threading
import time
from collections.abc import Awaitable, Callable, Iterable
from pathlib import Path
from types import FrameType
from typing import Any, Unpack

from textual import events, work
from textual.app import App, ComposeResult, SystemCommand
from textual.binding import Binding
from textual.containers import Container, Horizontal, Vertical
from textual.screen import ModalScreen, Screen
from textual.widget import Widget
from textual.widgets import Footer, Static

from stairbot.console import (
    choices,
    limp_question,
    motion_gate,
    paint,
    params_screen,
    plotting,
    recent,
    roomy,
    watching,
)
from stairbot.console.engine import ConsoleEngine, EngineHooks
from stairbot.console.freshness import age_key
from stairbot.console.help import COMMANDS, HelpScreen
from stairbot.console.limp_gate import stranded
from stairbot.console.mirror import MirrorState
from stairbot.console.robot_holder import SPEEDS
from stairbot.console.state import StateView
from stairbot.console.widgets.banner import Banner
from stairbot.console.widgets.estop import ESTOP_KEY, EStopButton
from stairbot.console.widgets.event_log import EventLog
from stairbot.console.widgets.link import LinkPanel
from stairbot.console.widgets.motors import MotorPanel
from stairbot.console.widgets.phase import PhasePanel
from stairbot.console.widgets.picture import StairsPicture
from stairbot.console.widgets.sensors import SensorPanel
from stairbot.console.widgets.top_view import TopViewPicture
from stairbot.console.widgets.trends import TrendsPanel
from stairbot.control.robot_config import load_config
from stairbot.errors import InputError, PortBusyError, StairbotError
from stairbot.inputs.config import RobotConfig
from stairbot.run.journaled import ResumePlan
from stairbot.run.runner import RunResult
from stairbot.views.top_view import RobotShape

REFRESH_HZ = 10.0

class StairbotConsole(App[None]):
    """The stairbot operator console."""

    CSS_PATH = "console.tcss"
    TITLE = "stairbot console"
    replaying = False
    """A recording played back (console/replay_app.py), not a robot."""
    # The footer shows what an operator needs at once, and fits 80 columns;
    # ? (the help screen) and ctrl+p list every key.
    BINDINGS = [
        Binding(ESTOP_KEY, "estop", "E-STOP", priority=True),
        Binding("c", "clear_estop", "clear"),
        Binding("s", "start('full')", "start"),
        Binding("p", "pause", "pause"),
        Binding("x", "stop_run", "stop"),
        Binding("q", "quit_console('q')", "quit"),
        Binding("question_mark", "help", "help", key_display="?"),
        Binding("k", "start('calibrate')", "calib", show=False),
        Binding("l", "limp_home", "limp home", show=False),
        Binding("u", "choose_robot", "robot", show=False),
        Binding("o", "choose_scenario", "scenario", show=False),
        Binding("f", "speed", "speed", show=False),
        Binding("r", "reset", "reset", show=False),
        Binding("w", "record", "rec", show=False),
        Binding("z", "zoom", "zoom", show=False),
        Binding("t", "top_view", "top view", show=False),
        Binding("g", "graphs", "graphs", show=False),
        Binding("v", "plots", "plot signals", show=False),
        Binding("h", "ask_control", "ask control", show=False),
        Binding("e", "event_filter", "filter events", show=False),
        Binding("slash", "event_search", "search events", show=False, key_display="/"),
        Binding("i", "parameters", "parameters", show=False),
        Binding("ctrl+q", "quit_console('ctrl+q')", "quit", show=False, priority=True),
        Binding("ctrl+c", "quit_console('Ctrl-C')", "stop, quit", show=False, priority=True),
    ]

    def __init__(self, engine: ConsoleEngine, url: str, scenario: str | None,
                 record: str | None = None) -> None:
        super().__init__()
        self.engine = engine
        self.state = engine.state
        self.url = url
        self.scenario = scenario
        self._record = record
        self.sharing = watching.Sharing()
        """The hub that shares this console's robot, or the client watching another's."""
        self.shown_key: object = None  # what the panels show (None: redraw at the next refresh)
        self.shown_event = 0  # the last event the list shows
        self.asking_quit = False
        """The console asks whether to quit (mid-run)."""
        self._sigint: Any = None  # the SIGINT handler before ours
        # The panels, kept here: refresh_view must reach them while a modal
        # screen is on top (app.query_one looks only at the top screen).
        # the line that says how things stand; a message too long for it, whole
        # in the event list
        self.banner = Banner(id="banner", told=self.state.note_once)
        self.picture = StairsPicture(id="picture")
        self.top_view = TopViewPicture(id="topview")
        self.top_shown = False
        """The picture shows the top view (t), not the side view."""
        self.robot_shape = RobotShape.of(engine.config)
        self.contact_said: str | None = None  # the wall contact told the operator
        side_pair = engine.config.sensors.has_side_pair
        self.sensors = SensorPanel(engine.config, side_pair=side_pair,
                                   id="sensors")
        self.motors = MotorPanel(id="motors")
        self.phase = PhasePanel(id="phase")
        self.link = LinkPanel(id="link")
        self.log_panel = EventLog(id="log")
        self.trends = TrendsPanel(engine.config.motors.lift_travel_per_turn,
                                  side_pair=side_pair, id="trends")
        self.plotting = plotting.Plotting()
        """The signals plotted (v) in the graphs' place (console/plotting.py)."""
        self.main_area = Container(id="main")  # a grid: console.tcss, console/roomy.py
        self.roomy = roomy.Roomy()
        self.small_notice = Static(id="too-small", markup=False)
        """Says the terminal is too small, in the panels' place (paint.lay_out)."""
        self.screen_rows: int | None = None  # the screen's height, as the last resize said
        self.graphs: bool | None = None
        """The operator's choice of graphs (g); None: by the screen's size."""
        self.own_config: RobotConfig | None = None
        """The console's own config while fake boards' is borrowed (console/board_robot.py)."""

    # -- layout ------------------------------------------------------------------
    def compose(self) -> ComposeResult:
        with Horizontal(id="top"):
            yield self.banner
            yield self.top_right()
        yield self.small_notice
        with self.main_area:
            with Vertical(id="left"):
                yield self.picture
                yield self.top_view
                yield self.trends
                yield self.plotting.panel
            with Vertical(id="right"):
                yield self.sensors
                yield self.motors
                yield self.phase
                yield self.link
            yield self.log_panel  # under the picture; roomy, under both (console/roomy.py)
        yield Footer(compact=True)

    def picture_note(self) -> str:
        """What the picture says when there is no pose to draw."""
        return ""

    def top_right(self) -> Widget:
        """What stands beside the banner: the emergency stop button."""
        return EStopButton(id="estop")

    def on_resize(self, event: events.Resize) -> None:
        # before the app's own size follows
        paint.lay_out(self, event.size.height, event.size.width)
        self.roomy.reset()

    def on_mount(self) -> None:
        # SIGINT (Ctrl-C where the terminal sends signals, or `kill -INT`):
        # the robot stops first, then the console asks, as for Ctrl-C typed.
        with contextlib.suppress(ValueError):  # not the main thread: left as it is
            self._sigint = signal.signal(signal.SIGINT, self._on_sigint)
        paint.lay_out(self)
        self.screen_change_signal.subscribe(self, self._on_screen_change)
        self.begin()

    def begin(self) -> None:
        """Once mounted: record if asked, redraw ten times a second, open the
        robot and read it while idle.  (A subclass replaces this, not
        ``on_mount``: Textual calls every class's ``on_mount``.)"""
        if self._record:
            choices.start_recording(self, self._record)
        self.refresh_view()
        self.set_interval(1 / REFRESH_HZ, self.refresh_view)
        self.open_robot(self.url, self.scenario)
        self.engine.start_polling()

    # -- the view ------------------------------------------------------------------
    def refresh_view(self) -> None:
        """Copy the live state and update every panel that changed (the ages
        of the values shown change with the wall clock alone)."""
        self.roomy.arrange(self)  # the panels' heights follow what they show, and the screen's
        view = self.state.view(events_after=self.shown_event)
        key = (view.version, age_key(view.read_age_s), age_key(view.top_age_s))
        if key == self.shown_key:
            return
        self.shown_key = key
        paint.show(self, view)

    def top_note(self, v: StateView) -> str:
        """Why the top view has nothing to draw ("": it has)."""
        if v.wired:
            return "no top view: a robot on a wire tells no pose seen from above"
        if v.plan is None:
            if v.status.robot in ("no robot", "connecting"):
                return "no robot open"
            return "no top view: this robot tells no pose seen from above"
        return ""

    # -- workers -------------------------------------------------------------------
    @work(thread=True, group="robot", exclusive=True, exit_on_error=False)
    def open_robot(self, url: str, scenario: str | None, clear_latches: bool = False) -> None:
        """Open a robot off the UI thread; on bad input say so and reopen the
        previous robot (if opening the new one closed it).  ``clear_latches``:
        the operator confirmed clearing the latches the boards hold.  A robot
        another console holds and shares is watched (console/watching.py)."""
        watching.stop_watching(self)
        watching.unshare(self)
        previous = (self.url, self.scenario) if self.engine.session is not None else None
        try:
            self.engine.open(url, scenario, clear_latches=clear_latches)
        except Exception as exc:  # noqa: BLE001 - any failure is a message, not a traceback
            if isinstance(exc, PortBusyError) and watching.watch(self, url,
                                                                 watching.SHARE_WAIT_S):
                self.url, self.scenario = url, scenario
                self._tell(f"another console controls {url}: watching it (h asks for "
                           "control)", "information")
                return
            why = _why(exc)
            message = why if why.startswith("cannot open ") else \
                f"cannot open {why}" if why.startswith(f"{url}: ") else \
                f"cannot open {url}: {why}"  # said once: 80x24 keeps the banner one line
            self._tell(message, "error")
            if previous is not None and self.engine.session is None and previous != (url,
                                                                                       scenario):
                try:
                    self.engine.open(*previous)
                    message = f"kept {previous[0]}: {message}"
                    watching.share(self)
                except Exception as again:  # noqa: BLE001
                    message += f"; {previous[0]} did not reopen either: {_why(again)}"
            if self.engine.session is None:
                self.state.set_status(robot="fault", severity="error", message=message)
            else:  # the robot open before is still (or again) the one in use
                self.state.set_status(severity="error", message=message)
            return
        self.url, self.scenario = url, scenario
        watching.share(self)
        if (unsaved := recent.remember(url)) is not None:  # the connection manager's Recent
            self._tell(unsaved, "warning")

    @work(thread=True, group="run", exclusive=False, exit_on_error=False)
    def run_program(self, mode: str, resume: ResumePlan | None = None) -> None:
        self._ran(self.engine.run(mode, resume))

    @work(thread=True, group="run", exclusive=False, exit_on_error=False)
    def limp_home(self) -> None:
        """The operator consented: the degraded stop's program carried on, limping home."""
        self._ran(self.engine.limp_home())

    def _ran(self, result: RunResult | None) -> None:
        """A run ended (worker thread): say how; after a degraded stop, ask
        whether to limp home, or say why the robot stays stopped."""
        if result is None:
            return
        self._tell(f"run {result.outcome}", "information")
        if self.engine.limp_offer is not None or self.engine.limp_refused \
                or stranded(self.state.view().degraded):
            self.from_thread(limp_question.after_stop, self)

    def _tell(self, message: str, severity: str) -> None:
        self.from_thread(self.say, message, severity)

    def from_thread(self, callback: Callable[..., object], *args: object) -> None:
        """Run ``callback(*args)`` on the UI thread (from another thread) and
        wait for it; nothing once the console has begun to quit, when no loop
        is left to run it on."""
        if self.is_running:
            self.call_from_thread(callback, *args)

    def say(self, message: str, severity: str = "information", *, keep: bool = True,
            timeout: float = 6) -> None:
        """Tell the operator: a toast, and (``keep``) a line in the event list
        that stays after the toast has gone.  The text is shown as it is, never
        parsed as markup: URLs, paths and drivers' messages hold brackets."""
        modal = isinstance(self.screen, ModalScreen)
        if keep or modal:  # a toast would cover a dialog's text: the event list keeps it
            self.state.note(message, severity)
        if not modal:
            self.notify(message, severity=severity, timeout=timeout,  # type: ignore[arg-type]
                        markup=False)

    def _on_screen_change(self, screen: Screen[Any]) -> None:
        """A dialog shown: the toasts go (each is in the event list), none
        covers what it asks."""
        if isinstance(screen, ModalScreen):
            self.clear_notifications()

    # -- actions -------------------------------------------------------------------
    async def on_event(self, event: events.Event) -> None:
        """The emergency stop key is taken here, before any screen or widget sees
        it: modal screens and text inputs would otherwise keep it from the
        app's bindings."""
        if (isinstance(event, events.Key) and not event.is_forwarded
                and event.key == ESTOP_KEY):
            event.stop()
            self.action_estop()
            return
        await super().on_event(event)

    async def run_action(self, action: Any, default_namespace: Any = None,
                         namespaces: Any = None) -> bool:
        """Every action, by key or by name: one that would reach the robot is
        refused while another console controls it."""
        if default_namespace in (None, self) and isinstance(action, str):
            name = action.split("(", 1)[0].rsplit(".", 1)[-1]
            if watching.blocked(self, name):
                return True
        return await super().run_action(action, default_namespace, namespaces)

    def action_estop(self) -> None:
        """Stop every motor now, whatever the console is doing (watching:
        the controlling console stops it)."""
        if watching.estop(self):
            return
        self.engine.estop()
        limp_question.withdraw(self)
        self.refresh_view()

    def action_clear_estop(self) -> None:
        """Clear the emergency stop once the operator confirms
        (:func:`~stairbot.console.motion_gate.clear_estop`)."""
        motion_gate.clear_estop(self)

    def action_start(self, mode: str) -> None:
        motion_gate.start(self, mode)

    def action_pause(self) -> None:
        motion_gate.pause(self)

    def action_limp_home(self) -> None:
        """Ask whether to limp home after a degraded stop
        (:func:`~stairbot.console.limp_question.ask`)."""
        limp_question.ask(self)

    def action_stop_run(self) -> None:
        if self.engine.running:
            self.engine.stop()
        else:
            self.say("no run is going on")

    def action_reset(self) -> None:
        if self.engine.running:
            self.say("stop the run first (x)", severity="warning")
        elif self.engine.session is not None and not self.engine.in_process:
            self.say("reset is for the in-process simulation (sim://)", severity="warning")
        else:
            self.log_panel.reset_log()
            self.open_robot(self.url, self.scenario)

    def action_choose_robot(self) -> None:
        choices.choose_robot(self)

    def action_choose_scenario(self) -> None:
        choices.choose_scenario(self)

    def action_speed(self) -> None:
        choices.speed(self)

    def action_record(self) -> None:
        choices.record(self)

    def action_help(self) -> None:
        if not isinstance(self.screen, HelpScreen):
            self.push_screen(HelpScreen())

    def action_graphs(self) -> None:
        choices.graphs(self)

    def action_plots(self) -> None:
        """Pick signals to plot (:func:`~stairbot.console.plotting.pick`)."""
        plotting.pick(self)

    def action_ask_control(self) -> None:
        watching.ask_control(self)

    def action_event_filter(self) -> None:
        choices.event_filter(self)

    def action_event_search(self) -> None:
        choices.event_search(self)

    def action_parameters(self) -> None:
        """The resolved config, its derived limits, and the edit of a
        runtime-safe value between runs (console/params_screen.py)."""
        params_screen.open_parameters(self)

    def action_zoom(self) -> None:
        choices.zoom(self)

    def action_top_view(self) -> None:
        choices.top_view(self)

    def get_system_commands(self, screen: Screen) -> Iterable[SystemCommand]:
        yield from super().get_system_commands(screen)
        for action, title, help_text in COMMANDS:
            yield SystemCommand(title, help_text, self._runner(action))

    def _runner(self, action: str) -> Callable[[], Awaitable[None]]:
        async def go() -> None:
            await self.run_action(action)
        return go

    def on_unmount(self) -> None:
        watching.close(self)
        self.engine.shutdown()
        if self._sigint is not None:
            with contextlib.suppress(ValueError):
                signal.signal(signal.SIGINT, self._sigint)

    # -- quitting ------------------------------------------------------------------
    def action_quit_console(self, key: str = "q") -> None:
        """Quit; mid-run the robot stops first, then the console asks
        (:func:`~stairbot.console.motion_gate.quit_console`)."""
        motion_gate.quit_console(self, key)

    def _on_sigint(self, _sig: int, _frame: FrameType | None) -> None:
        def stop_then_ask() -> None:
            if self.engine.running and not self.engine.latched:
                self.engine.estop("SIGINT")
            self.from_thread(self.action_quit_console, "SIGINT")
        threading.Thread(target=stop_then_ask, name="SIGINT emergency stop",
                         daemon=True).start()


def _why(exc: Exception) -> str:
    """An error as the operator reads it: our own errors say it all; anything
    else is named by its type."""
    if isinstance(exc, StairbotError | OSError):
        return str(exc)
    return f"{type(exc).__name__}: {exc}"


def build_app(config: RobotConfig | str | Path | None = None, *, url: str = "sim://",
              scenario: str | None = None, record: str | None = None, speed: str = "1x",
              ages_wall: Callable[[], float] = time.monotonic,
              **engine_hooks: Unpack[EngineHooks]) -> StairbotConsole:
    """Build the console.  ``config`` is a RobotConfig, a file, or None for the
    shipped robot (raises ConfigError for a bad file).  ``ages_wall`` is the
    clock the values' ages go by (a test that pins the picture stops it).
    ``engine_hooks`` (open_fn, run_fn, control_fn, wall, sleep) replace the
    engine's defaults."""
    cfg = config if isinstance(config, RobotConfig) else load_config(config)
    if speed not in SPEEDS:
        raise InputError("--speed", None, f"{speed!r}; allowed: {', '.join(SPEEDS)}")
    state = MirrorState(url=url, wall=ages_wall)
    engine = ConsoleEngine(state, cfg, **engine_hooks)
    engine.set_speed(speed)
    return StairbotConsole(engine, url, scenario, record)
