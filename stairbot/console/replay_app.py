"""The console playing a recording (``stairbot replay FILE``, ``stairbot
console --replay FILE``): the same panels as a live console, drawn from a
:class:`~stairbot.console.replay.ReplayPlayer`, with the keys of a player
(play/pause, speed, seek) instead of a robot's.

Nothing here opens a robot or commands one.  The banner says REPLAY and
the file; where the E-STOP button stands, a mark says there is no robot.
The keys that would move a robot (s, k, c, u, r, o, x, w, f, l, h) say
"replay: no robot" and do nothing else.  Space, the emergency stop
everywhere else, stops nothing here and says so, loudly -- and does not
pause the replay either: an operator who pressed it thinking this was the
live robot must not see the picture stand still and believe the robot
stopped.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable

from rich.text import Text
from textual.app import SystemCommand
from textual.binding import Binding
from textual.screen import Screen
from textual.widget import Widget
from textual.widgets import Static

from stairbot.console import plotting
from stairbot.console.app import REFRESH_HZ, StairbotConsole
from stairbot.console.engine import ConsoleEngine
from stairbot.console.help import HelpScreen
from stairbot.console.replay import ReplayPlayer, speed_name
from stairbot.console.state import StateView
from stairbot.console.widgets.estop import ESTOP_KEY
from stairbot.control.robot_config import load_config
from stairbot.inputs.config import RobotConfig
from stairbot.recording.replay_source import ReplaySource

NO_ROBOT = "replay: no robot"
KEY_WORDS = {
    "s": "s starts a run", "k": "k calibrates", "c": "c clears an emergency stop",
    "u": "u opens a robot", "r": "r resets the simulation", "o": "o picks a scenario",
    "x": "x stops a run", "w": "w records a run", "f": "f sets the simulation's speed",
    "l": "l limps home after a degraded stop",
    "h": "h asks another console for control of its robot",
}
"""The live console's keys that would reach a robot, and what each does there."""

SEEK_SHORT_S = 1.0
SEEK_LONG_S = 5.0

REPLAY_HELP = f"""\
REPLAY: a recording played back.  No robot is connected:
nothing here moves or stops a robot.

KEYS
  p         play / pause (at the end: from the start again)
  + -       faster / slower: {", ".join(speed_name(s) for s in (0.25, 0.5, 1, 2, 5, 10, 50))}
  ← →       back / forward {SEEK_SHORT_S:g} s
  shift+← → back / forward {SEEK_LONG_S:g} s (also [ and ])
  Home End  the start / the end
  g         graphs (pitch, distance sensors, lifts; last 30 s)
  v         plot signals you pick, with a timeline of the
            recording's errors, pauses and phase changes
  , .       to the previous / next of those markers
  e /       the event list: filter by kind / search its text
  z         picture zoom
  t         top view: a recording holds no pose seen from
            above, so it says so (t again: the side view)
  q         quit (also Ctrl+Q, Ctrl-C)
  ?         this help          Ctrl+P  every action by name
  space     a live console's EMERGENCY STOP: here it says
            there is no robot to stop (the replay goes on)
  s k c u r o x w f l h   say "replay: no robot"

READING THE SCREEN
  The banner: REPLAY, ▶ playing ⏸ paused ■ at the end, the
  speed, the position t = 12.3 s / 85.0 s (the robot's clock),
  the file.  Every value is the recording's, drawn where the
  live console draws it.  Ages are the recording's: a value
  recorded 2 s before the position is 2 s old, STALE where the
  recording has a gap.
  A JSON-lines record holds events alone: no sensor, motor or
  picture, only the event list and the phases over time.
  Phase: steps climbed and treads are not recorded (—).

  Escape or ? closes this help.
"""


class ReplayConsole(StairbotConsole, inherit_bindings=False):
    """The console on a recording."""

    replaying = True
    BINDINGS = [
        # space: on_event takes it first, on every screen (as in a live console)
        Binding(ESTOP_KEY, "estop", "no robot", show=False, priority=True),
        Binding("p", "play", "play/pause"),
        Binding("left", "seek(-1)", "-1 s", key_display="←", priority=True),
        Binding("right", "seek(1)", "+1 s", key_display="→", priority=True),
        Binding("shift+left,left_square_bracket", "seek(-5)", "-5 s", show=False,
                priority=True),
        Binding("shift+right,right_square_bracket", "seek(5)", "+5 s", show=False,
                priority=True),
        Binding("home", "seek_to('start')", "start", show=False, priority=True),
        Binding("end", "seek_to('end')", "end", show=False, priority=True),
        Binding("plus,equals_sign", "faster", "faster", key_display="+"),
        Binding("minus", "slower", "slower", key_display="-"),
        Binding("q", "quit_console('q')", "quit"),
        Binding("question_mark", "help", "help", key_display="?"),
        Binding("g", "graphs", "graphs", show=False),
        Binding("v", "plots", "plot signals", show=False),
        Binding("comma", "marker(-1)", "previous marker", show=False, key_display=","),
        Binding("full_stop", "marker(1)", "next marker", show=False, key_display="."),
        Binding("z", "zoom", "zoom", show=False),
        Binding("t", "top_view", "top view", show=False),
        Binding("ctrl+q", "quit_console('ctrl+q')", "quit", show=False, priority=True),
        Binding("ctrl+c", "quit_console('Ctrl-C')", "quit", show=False, priority=True),
        *(Binding(key, f"no_robot('{key}')", NO_ROBOT, show=False) for key in KEY_WORDS),
    ]
    COMMANDS_REPLAY: tuple[tuple[str, str, str], ...] = (
        ("play", "Play / pause", "Play the recording or hold it (key: p)"),
        ("faster", "Faster", "Play faster (key: +)"),
        ("slower", "Slower", "Play slower (key: -)"),
        ("seek_to('start')", "To the start", "Back to the recording's start (key: Home)"),
        ("seek_to('end')", "To the end", "On to the recording's end (key: End)"),
        ("graphs", "Graphs", "Pitch, distance sensors and lifts over 30 s (key: g)"),
        ("plots", "Plot signals", "Pick signals to plot, with the recording's markers (key: v)"),
        ("marker(-1)", "Previous marker", "Back to the previous error, pause or phase (key: ,)"),
        ("marker(1)", "Next marker", "On to the next error, pause or phase (key: .)"),
        ("zoom", "Zoom the picture", "Auto, whole flight, or follow the robot (key: z)"),
        ("top_view", "Top view / side view", "The top view: not in a recording (key: t)"),
        ("help", "Help", "Every key, and how to read the screen (key: ?)"),
    )

    def __init__(self, player: ReplayPlayer, engine: ConsoleEngine) -> None:
        super().__init__(engine, player.robot_name, player.source.parts[0].scenario)
        self.player = player
        self.plotting.replay(player)
        self._rewinds = player.rewinds
        self.title = f"stairbot replay · {player.source.path}"

    def top_right(self) -> Widget:
        return Static(Text(" REPLAY · no robot ", "bold"), id="replay-mark")

    def picture_note(self) -> str:
        if self.player.source.kind == "jsonl":
            return "no picture: a JSON-lines record holds events alone"
        return "no pose recorded yet" if self.player.source.ticks else "no pose recorded"

    def top_note(self, v: StateView) -> str:
        # What is recorded is the side view's pose, in the frame the simulation
        # was in (a landing's second flight switches it) and without the frame:
        # drawn in flight 1's frame it could be wrong, so it is not drawn.
        return ("no top view: a recording holds no pose seen from above (in flight 1's "
                "frame)")

    def begin(self) -> None:
        """Once mounted: play, drawing ten times a second.  No robot is opened
        and nothing polls one."""
        for note in self.player.source.notes:  # the banner keeps them too
            self.say(note, "warning", keep=False, timeout=10)
        self.advance()
        self.set_interval(1 / REFRESH_HZ, self.advance)

    def advance(self) -> None:
        """Move the player on by its clock and draw what it wrote."""
        self.player.update()
        self.show_player()

    def show_player(self) -> None:
        player, state = self.player, self.state
        if player.rewinds != self._rewinds:  # sought back: the list is played again
            self._rewinds = player.rewinds
            self.log_panel.reset_log()
        state.set_speed(speed_name(player.speed))
        state.set_status(robot="replay", message=self.banner_line(), severity="info")
        self.refresh_view()

    def banner_line(self) -> str:
        """``▶ 1× · t = 12.3 s / 85.0 s · FILE · recorded on sim://, default``
        and what the recording lacks."""
        src = self.player.source
        parts = [self.player.line(), src.path]
        if src.kind == "mcap":
            parts.append(self.player.part_line())
        if src.kind == "jsonl":
            parts.append("JSON lines: events only, no sensor or motor values")
        if not src.complete:
            parts.append(f"cut short: the file ends at {src.end_s:.1f} s")
        return " · ".join(parts + src.notes)

    # -- the player's keys ---------------------------------------------------------
    def action_play(self) -> None:
        self.player.toggle()
        self.show_player()

    def action_faster(self) -> None:
        self.player.faster()
        self.show_player()

    def action_slower(self) -> None:
        self.player.slower()
        self.show_player()

    def action_seek(self, delta_s: float) -> None:
        self.player.step(float(delta_s))
        self.show_player()

    def action_seek_to(self, where: str) -> None:
        self.player.seek(self.player.start_s if where == "start" else self.player.end_s)
        self.show_player()

    def action_marker(self, direction: int) -> None:
        """To the next (1) or previous (-1) error, pause or phase change."""
        plotting.jump(self, int(direction))
        self.show_player()

    # -- what a live console does to a robot -------------------------------------
    def open_robot(self, url: str, scenario: str | None,  # type: ignore[override]
                   clear_latches: bool = False) -> None:
        """Never: a replay opens no robot (the live console's worker is not run)."""
        self.say(f"{NO_ROBOT}: no robot is opened in a replay", "warning", keep=False)

    def action_estop(self) -> None:
        self.say(f"{NO_ROBOT} to stop: this is a recording ({self.player.source.path}); "
                 "nothing here moves a robot.  A robot running now is stopped from its own "
                 "console (space there) or its own E-STOP.", "error", keep=False, timeout=10)

    def action_no_robot(self, key: str) -> None:
        self.say(f"{NO_ROBOT}: {KEY_WORDS.get(key, key)} on a live console "
                 "(stairbot console); this is a recording", "warning", keep=False)

    def action_help(self) -> None:
        if not isinstance(self.screen, HelpScreen):
            self.push_screen(HelpScreen(REPLAY_HELP))

    def get_system_commands(self, screen: Screen) -> Iterable[SystemCommand]:
        yield from super(StairbotConsole, self).get_system_commands(screen)  # App's own
        for action, title, help_text in self.COMMANDS_REPLAY:
            yield SystemCommand(title, help_text, self._runner(action))


def build_replay_app(source: ReplaySource, *, speed: float = 1.0, playing: bool = True,
                     clock: Callable[[], float] = time.monotonic,
                     config: RobotConfig | None = None) -> ReplayConsole:
    """The console playing ``source``, by ``clock`` (a test passes its own).
    ``config``: the robot to draw with when the recording holds none (None:
    the reference robot)."""
    cfg = source.config or config or load_config(None)
    if source.config is None and source.kind == "mcap":
        source.notes.append(f"drawn with {cfg.source}: the recording names no robot config")
    player = ReplayPlayer(source, cfg, clock, speed=speed, playing=playing)
    return ReplayConsole(player, ConsoleEngine(player.state, cfg))
