"""The help screen (``?``): every key, and how to read the screen; and
every action by name, for the command palette (:data:`COMMANDS`).

Its lines fit :data:`WIDTH` columns: the dialog's width (``.help`` in
console.tcss, 72) less its border, padding and scroll bar; a longer one
wraps at 80x24 into a line that reads as two."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Static

WIDTH = 64

# (action, palette title, palette help) for every operator action.
COMMANDS: tuple[tuple[str, str, str], ...] = (
    ("estop", "EMERGENCY STOP", "Stop every motor now (key: space)"),
    ("clear_estop", "Clear emergency stop", "Allow motion again; resume with p (key: c)"),
    ("start('full')", "Start full run", "Calibrate, climb, descend (key: s)"),
    ("start('calibrate')", "Calibrate only", "Run the calibration and stop (key: k)"),
    ("pause", "Pause / resume", "Hold the run where it is, or go on (key: p)"),
    ("stop_run", "Stop the run", "End the run, motors stopped (key: x)"),
    ("limp_home", "Limp home", "After a degraded stop: come home on the remaining "
                               "sensors, once you consent (key: l)"),
    ("reset", "Reset the simulated scenario", "Reopen the simulation at its start (key: r)"),
    ("choose_robot", "Connect to a robot", "pick one from the list (fake boards, serial "
     "ports, CAN buses, sim://, recent) or type its URL (key: u)"),
    ("choose_scenario", "Choose scenario", "A scenario file or shipped name (key: o)"),
    ("speed", "Simulation speed", "Cycle 1×, 10×, as fast as possible (key: f)"),
    ("record", "Record events", "Start/stop recording: FILE.mcap every tick as MCAP, else "
                                "the events as JSON lines (key: w)"),
    ("zoom", "Zoom the picture", "Auto, whole flight, or follow the robot (key: z)"),
    ("top_view", "Top view / side view", "The stairwell and the robot seen from above, or "
                                         "the side view again (key: t)"),
    ("graphs", "Graphs", "Pitch, distance sensors and lifts over the last 30 s (key: g)"),
    ("plots", "Plot signals", "Pick up to 4 signals (sensors, motors, lifts, IMU, link) "
                              "to plot in the graphs' place (key: v)"),
    ("ask_control", "Ask for control", "Watching another console's robot: ask its "
                                       "operator to hand control over (key: h)"),
    ("event_filter", "Filter the events", "Every event, errors, warnings, phases, the "
                                           "link's: the next (key: e)"),
    ("event_search", "Search the events", "Only the events whose text holds a word "
                                          "(key: /)"),
    ("parameters", "Parameters", "The robot config, its derived limits; change a "
                                 "runtime-safe value between runs (key: i)"),
    ("help", "Help", "Every key, and how to read the screen (key: ?)"),
)

HELP = """\
KEYS
  space   EMERGENCY STOP: every motor stops at once, from any
          screen, even over a prompt; latched until c
  c       clear the emergency stop (asks first: look at the
          robot)
  s       start the full run      k  calibrate only
  p       pause / resume          x  stop the run
  l       limp home: after a degraded stop (a sensor lost on the
          stairs), asks whether the robot may come down on the
          sensors that remain; the console asks at the stop
  q       quit (mid-run: the robot stops first, then it asks);
          Ctrl+Q and Ctrl-C do the same
  u       connect: pick a robot   o  scenario
  f       simulation speed        r  reset the simulation
  w       record events to a file (never over an existing one)
  z       picture zoom            ?  this help
  t       top view: the stairwell and the robot seen from above,
          in the side view's place (t again: the side view)
  g       graphs: pitch, distance sensors, lifts over the last
          30 s of robot time (36 rows or more: under the
          picture; fewer: in its place until g again)
  v       plot signals: pick up to 4 (each sensor, motor speed
          and count, lifts, pitch and roll, link figures) to
          plot over robot time in the graphs' place; none
          picked: the graphs again
  e       the event list: every event, errors, warnings (and
          errors), phases, the link's; e again: the next
  /       the event list: only events whose text holds a word
          (empty: every event)
  h       watching a robot another console controls: ask that
          console's operator to hand control over
  i       parameters: the robot config, what the controller
          works from; between runs, change a value marked ✎
          (a new file extends the config: a diff first)
  Ctrl+P  every action by name

READING THE SCREEN
  Banner, first line: the state (READY, RUNNING, PAUSED, ENDED,
  FAULT), E-STOP and who latched it (operator, or automatic:
  why), DEGRADED while a run limps home on the sensors that
  remain (which is out, the survivor its pair runs on, the
  speed) and after it, LIVE or DOWN and how long ago the robot
  was read, the boards, the URL.  Under it: what to know now.
  WATCHING first: another console (a browser tab, a terminal)
  has the robot open and controls it; this one shows what that
  one shows, its keys that would reach the robot say so, and
  space sends that console the emergency stop.
  Every panel says how old its values are; values not read for
  1.5 s are dimmed and marked STALE: they are not live (no
  colour, no arrow: ? for a motor).
  Questions that let the robot move take yes typed and Enter;
  Escape answers no.
  Sensors: front R/L look ahead (SFR, SFL), back R/L look down
  (SBR, SBL); side R/L look right and left (SSR, SSL), on a
  robot with the side pair only; ok, out (of range: the value
  is the sensor's limit), old (the sensor's own reading is
  stale), ERROR, none (no reading of it); LOST: a limp home goes
  without it, its pair runs on the other ("runs on SFL").
  Motors: ▶ forward ◀ back; a lift shows the segment that moves:
  1▲ segment 1 rises, 2▼ segment 2 sinks (segments 1 front, 2
  middle, 3 back, coloured as in the picture).  With no run
  going, a lift's arrow is its end segment against segment 2.
  Phase: what the robot is doing, the seed's name for it
  beneath.
  Top view (t): flight 1 runs right as in the side view, its
  left side up; risers grey, walls white, a landing's second
  flight beyond it; the robot's footprint (segments coloured as
  in the picture), a white tick at its nose.  A wall contact is
  red, under it and on the wall: the simulation lets the robot
  through a wall the side view does not hold.  Simulation only.
  Graphs: each line scaled to its own range, written after it;
  they stop when the readings stop, and dim with them when
  STALE.
  Events: the run's events and everything the console said,
  the newest in view; scrolled up, the list holds its place
  until scrolled back to its end.

  Escape or ? closes this help.
"""


class HelpScreen(ModalScreen[None]):
    """Every key and how to read the screen; Escape, q or ? closes it."""

    BINDINGS = [Binding("escape,question_mark,q", "close", "close")]

    def __init__(self, text: str = HELP) -> None:
        super().__init__()
        self.text = text

    def compose(self) -> ComposeResult:
        with VerticalScroll(classes="dialog help"):
            yield Static(self.text, markup=False)

    def action_close(self) -> None:
        self.dismiss(None)
