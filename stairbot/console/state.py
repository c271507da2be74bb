"""The latest state of the robot and the run, shared between the run thread
(which writes it every tick) and the UI (which reads a copy ten times a second).

Every method takes one lock for a short time; the UI never waits for a tick.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

from stairbot.console.history import History, Row
from stairbot.events import Event, EventKind
from stairbot.hardware import MotorId, Snapshot
from stairbot.run.runner import RunResult
from stairbot.views.side_view import SceneView
from stairbot.views.top_view import TopPlan, TopPose

LOG_LENGTH = 1000
NOTE_KINDS = {"information": EventKind.INFO, "warning": EventKind.WARNING,
              "error": EventKind.ERROR}
CONSOLE = "console"  # the phase field of what the console itself says


@dataclass(frozen=True)
class RunStatus:
    """Where the console stands, for the banner."""

    robot: str = "no robot"  # "connecting" | "ready" | "running" | "ended" | "fault" | "no robot"
    estopped: bool = False
    paused: bool = False
    message: str = ""  # how the run ended, or what went wrong
    severity: str = "info"  # info | good | warning | error
    latch: str = ""  # who latched the emergency stop: "operator", or "automatic: why"


@dataclass(frozen=True)
class StateView:
    """An immutable copy of the live state, taken by the UI."""

    version: int
    url: str
    scenario: str
    simulated: bool
    wired: bool  # no in-process world to draw: a driver on a serial link or CAN bus
    status: RunStatus
    snapshot: Snapshot | None
    read_age_s: float | None  # wall seconds since the snapshot was read (None: never)
    commands: dict[MotorId, float]
    ticks: int
    phase: str
    phase_id: str  # the phase's value ("ascent_lift_first"); "" before a run
    flow: str
    context: dict[str, Any]
    scene: SceneView | None
    stairs: tuple[tuple[float, float], ...]
    health: dict[str, float]
    result: RunResult | None
    speed: str
    recording: str | None
    events: tuple[tuple[int, Event], ...] = field(default=())
    history: tuple[Row, ...] = field(default=())
    """The last readings by robot time, for the graphs (console/history.py)."""
    plan: TopPlan | None = None
    """The stairwell seen from above, for the top view; None: this robot tells
    no pose seen from above (a robot on a wire, a replay)."""
    top: TopPose | None = None
    """The robot seen from above, as last taken (None: none yet)."""
    top_age_s: float | None = None
    """Wall seconds since ``top`` was taken (None: never)."""
    degraded: Event | None = None
    """The run's degraded stop, as its event told it (its ``data["degraded"]``:
    what failed, where, the lifts, what follows); None: none this run."""
    limping: tuple[str, ...] = ()
    """The sensors lost while the robot limps home, each pair's survivor
    standing in for its partner (empty: not limping)."""
    limp_end: str = ""
    """How the program that limped home ended (its END's outcome,
    "came_home_degraded" or another); "": it has not."""
    boards: str = ""
    """The boards' identity (``motor #12 · sensor #34``; "": not a robot on a
    wire, or not known yet)."""
    watching: str = ""
    """Who controls the robot shown, when it is not this console (console/
    sharing.py: this one only watches); "": this console."""


class LiveState:
    """Thread-safe latest state.  Writers: the run thread and the UI's actions."""

    def __init__(self, *, url: str = "", scenario: str = "", simulated: bool = True,
                 wall: Callable[[], float] = time.monotonic) -> None:
        """``wall``: the clock the values' ages go by (a replay passes its
        position in the recording: the ages are the recording's)."""
        self._lock = threading.Lock()
        self._wall = wall
        self._read_at: float | None = None  # wall time of the last reading taken
        self._version = 0
        self._url = url
        self._scenario = scenario
        self._simulated = simulated
        self._wired = False
        self._status = RunStatus()
        self._snapshot: Snapshot | None = None
        self._commands: dict[MotorId, float] = {}
        self._ticks = 0
        self._phase = "—"
        self._phase_id = ""
        self._flow = "idle"
        self._context: dict[str, Any] = {}
        self._scene: SceneView | None = None
        self._plan: TopPlan | None = None
        self._top: TopPose | None = None
        self._top_at: float | None = None
        self._stairs: tuple[tuple[float, float], ...] = ()
        self._health: dict[str, float] = {}
        self._result: RunResult | None = None
        self._speed = "max"
        self._recording: str | None = None
        self._boards = ""
        self._events: deque[tuple[int, Event]] = deque(maxlen=LOG_LENGTH)
        self._heard_s = 0.0
        """The robot's clock as last heard from: its latest reading or run event
        (a console note is listed at it, after what came before)."""
        self._event_seq = 0
        self._history = History()
        self._degraded: Event | None = None
        self._limping: tuple[str, ...] = ()
        self._limp_end = ""

    # -- writers -----------------------------------------------------------------
    def _bump(self) -> None:
        self._version += 1

    def set_robot(self, url: str, scenario: str, simulated: bool,
                  stairs: tuple[tuple[float, float], ...] = (), wired: bool = False,
                  plan: TopPlan | None = None) -> None:
        """A new robot was opened: forget the previous one's readings.  ``plan``:
        its stairwell seen from above, when it tells its pose seen from above."""
        with self._lock:
            self._plan, self._top, self._top_at = plan, None, None
            self._url, self._scenario, self._simulated = url, scenario, simulated
            self._wired = wired
            self._snapshot, self._commands, self._ticks = None, {}, 0
            self._read_at = None
            self._phase, self._flow, self._context = "—", "idle", {}
            self._phase_id = ""
            self._scene, self._stairs, self._health, self._result = None, stairs, {}, None
            self._history.clear()
            self._degraded, self._limping, self._limp_end = None, (), ""
            self._boards = ""
            self._heard_s = 0.0  # another robot, another clock
            self._bump()

    def set_boards(self, boards: str) -> None:
        """The opened boards' identity, as the banner shows it."""
        with self._lock:
            self._boards = boards
            self._bump()

    def rename(self, url: str, scenario: str, stairs: tuple[tuple[float, float], ...]) -> None:
        """Name another robot, keeping what was read (a replay's next part)."""
        with self._lock:
            self._url, self._scenario, self._stairs = url, scenario, stairs
            self._bump()

    def set_status(self, *, robot: str | None = None, estopped: bool | None = None,
                   paused: bool | None = None, message: str | None = None,
                   severity: str | None = None, latch: str | None = None) -> None:
        """Change the fields given (None: left as it is)."""
        with self._lock:
            st = self._status
            self._status = replace(
                st,
                robot=st.robot if robot is None else robot,
                estopped=st.estopped if estopped is None else estopped,
                paused=st.paused if paused is None else paused,
                message=st.message if message is None else message,
                severity=st.severity if severity is None else severity,
                latch=st.latch if latch is None else latch,
            )
            self._bump()

    def on_read(self, snap: Snapshot, at: float | None = None) -> None:
        """``snap`` was read ``at`` on the ages' clock (None: now)."""
        with self._lock:
            self._snapshot = snap
            self._heard_s = max(self._heard_s, snap.time_s)
            self._read_at = self._wall() if at is None else at
            self._ticks += 1
            self._history.add(snap)
            if snap.health:
                self._health = dict(snap.health)
            self._bump()

    def on_command(self, speeds: dict[MotorId, float]) -> None:
        with self._lock:
            self._commands = speeds
            self._bump()

    def on_phase(self, label: str, flow: str, context: dict[str, Any] | None,
                 phase_id: str = "") -> None:
        with self._lock:
            self._phase, self._flow, self._phase_id = label, flow, phase_id
            if context is not None:
                self._context = context
            self._bump()

    def on_scene(self, scene: SceneView) -> None:
        with self._lock:
            self._scene = scene
            self._bump()

    def on_top(self, pose: TopPose | None, at: float | None = None) -> None:
        """The robot seen from above, taken ``at`` on the ages' clock (None: now);
        ``pose`` None: it can no longer be taken (the view shows none)."""
        with self._lock:
            self._top = pose
            self._top_at = None if pose is None else (self._wall() if at is None else at)
            self._bump()

    def on_event(self, event: Event) -> None:
        with self._lock:
            self._event_seq += 1
            self._events.append((self._event_seq, event))
            self._heard_s = max(self._heard_s, event.time_s)
            if event.kind.value == "link" and event.data:
                self._health.update(
                    {k: float(v) for k, v in event.data.items() if isinstance(v, int | float)}
                )
            self._limp_told(event)
            self._bump()

    def _limp_told(self, event: Event) -> None:
        """Follow a degraded stop and the limp home by the run's own events (a
        replay's too): the stop's WARNING, the RESUME that limps on (its
        ``limp``: the sensors lost, or the limp's record when a consent
        reopened the program), its END, and a fresh program's start, which
        ends them all."""
        data = event.data
        if not data:
            return
        if event.kind is EventKind.PHASE and data.get("why") == "program start":
            self._degraded, self._limping, self._limp_end = None, (), ""
        elif event.kind is EventKind.END and self._limping:
            self._limp_end = str(data.get("outcome", ""))
        elif event.kind is EventKind.WARNING and isinstance(data.get("degraded"), dict):
            self._degraded = event
        elif event.kind is EventKind.RESUME and "limp" in data:
            limp = data["limp"]
            lost = limp.get("lost") if isinstance(limp, dict) else limp
            if isinstance(lost, list) and lost:
                self._limping, self._limp_end = tuple(str(s) for s in lost), ""

    def clear_events(self) -> None:
        """Forget the event list (a replay sought back plays it again), and
        what it told of a degraded stop."""
        with self._lock:
            self._events.clear()
            self._heard_s = 0.0
            self._degraded, self._limping, self._limp_end = None, (), ""
            self._bump()

    def note(self, message: str, severity: str = "information") -> None:
        """What the console told the operator, kept in the event list (on the
        robot's clock as last heard from, so after every event listed before
        it; not in the record: the run's events are what `stairbot run
        --record` writes)."""
        self.on_event(Event(self._heard_s, NOTE_KINDS.get(severity, EventKind.INFO), message,
                            CONSOLE))

    def note_once(self, message: str, severity: str = "information") -> None:
        """:meth:`note`, unless one of the last few events says it already."""
        with self._lock:
            recent = list(self._events)[-5:]
        if all(event.message != message for _, event in recent):
            self.note(message, severity)

    def on_result(self, result: RunResult | None) -> None:
        with self._lock:
            self._result = result
            self._bump()

    def set_speed(self, speed: str) -> None:
        with self._lock:
            self._speed = speed
            self._bump()

    def set_recording(self, path: str | None) -> None:
        with self._lock:
            self._recording = path
            self._bump()

    # -- readers -----------------------------------------------------------------
    @property
    def snapshot(self) -> Snapshot | None:
        """The last snapshot read (None: none since the robot was opened),
        without copying the rest as :meth:`view` does."""
        with self._lock:
            return self._snapshot

    def readings(self) -> tuple[Snapshot, ...]:
        """Every reading of the graphs' window, oldest first (console/history.py),
        without copying the rest as :meth:`view` does: the plots' (key v)."""
        with self._lock:
            return self._history.readings()

    @property
    def version(self) -> int:
        with self._lock:
            return self._version

    def view(self, events_after: int = 0) -> StateView:
        """A copy of everything; ``events`` holds only those numbered after ``events_after``."""
        with self._lock:
            return StateView(
                version=self._version,
                url=self._url,
                scenario=self._scenario,
                simulated=self._simulated,
                wired=self._wired,
                status=self._status,
                snapshot=self._snapshot,
                read_age_s=None if self._read_at is None else self._wall() - self._read_at,
                commands=dict(self._commands),
                ticks=self._ticks,
                phase=self._phase,
                phase_id=self._phase_id,
                flow=self._flow,
                context=dict(self._context),
                scene=self._scene,
                stairs=self._stairs,
                health=dict(self._health),
                result=self._result,
                speed=self._speed,
                recording=self._recording,
                events=tuple(e for e in self._events if e[0] > events_after),
                history=self._history.rows(),
                plan=self._plan,
                top=self._top,
                top_age_s=None if self._top_at is None else self._wall() - self._top_at,
                degraded=self._degraded,
                limping=self._limping,
                limp_end=self._limp_end,
                boards=self._boards,
            )
