"""The robot and clock as the console hands them to the run loop: every call
under one lock, what was read and sent copied into the live state, a latched
emergency stop that turns every command into a stop, pacing to a chosen
simulation speed; and the event recorder (JSON lines).
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable
from typing import Protocol

from stairbot.console.state import LiveState
from stairbot.hardware import (
    ZERO_SPEEDS,
    Clock,
    EstopsFromAnyThread,
    HasTruth,
    Robot,
    Snapshot,
    Speeds,
    Truth,
)
from stairbot.views.side_view import SceneView
from stairbot.views.top_view import TopPose

SCENE_PERIOD_S = 0.04  # wall seconds between pictures taken from the simulation


class WatchedRobot:
    """A Robot that passes every call on under a lock, tells the live state what
    it read and sent, and obeys a latched emergency stop: while it is set every
    command becomes a stop of every motor."""

    def __init__(self, inner: Robot, state: LiveState, lock: threading.RLock,
                 scene: Callable[[], SceneView] | None = None,
                 wall: Callable[[], float] = time.monotonic,
                 top: Callable[[], TopPose | None] | None = None) -> None:
        self.inner = inner
        self._estop_unlocked = isinstance(inner, EstopsFromAnyThread)  # asked once, not per press
        self._state = state
        self._lock = lock
        self._scene = scene
        self._top = top
        self._wall = wall
        self._last_scene = -1.0
        self._estop = threading.Event()
        self._estop_sent = False  # the inner robot's estop() was called for this latch
        self.estop_tick: int | None = None  # the tick count when the stop reached the robot
        self.ticks = 0
        self.sent: Speeds | None = None
        """The speeds commanded since the last read (None: none, or the
        latched e-stop turned the command into a stop): what a record keeps."""

    @property
    def estopped(self) -> bool:
        return self._estop.is_set()

    def read(self) -> Snapshot:
        with self._lock:
            snap = self.inner.read()
            self.ticks += 1
            self.sent = None
            self._state.on_read(snap)
            self._maybe_scene()
        return snap

    def _maybe_scene(self, force: bool = False) -> None:
        now = self._wall()
        if ((self._scene is None and self._top is None)
                or (not force and now - self._last_scene < SCENE_PERIOD_S)):
            return
        self._last_scene = now
        if self._scene is not None:
            try:
                scene = self._scene()
            except Exception as exc:  # noqa: BLE001 - a picture must never stop the robot
                self._scene = None
                self._state.set_status(message=f"no picture: {exc}", severity="warning")
            else:
                self._state.on_scene(scene)
        if self._top is not None:
            try:
                pose = self._top()
            except Exception as exc:  # noqa: BLE001 - nor must the top view
                self._top, pose = None, None
                self._state.set_status(message=f"no top view: {exc}", severity="warning")
            self._state.on_top(pose)  # None: no pose to show, never the last one as live

    def refresh_scene(self) -> None:
        """Take a picture now (under the lock)."""
        with self._lock:
            self._maybe_scene(force=True)

    def command(self, speeds: Speeds) -> None:
        with self._lock:
            if self._estop.is_set():
                self.inner.stop_all()
                self._state.on_command(dict(ZERO_SPEEDS))
            else:
                self.inner.command(speeds)
                self.sent = speeds
                self._state.on_command(dict(speeds))

    def stop_all(self) -> None:
        with self._lock:
            self.inner.stop_all()
            self._state.on_command(dict(ZERO_SPEEDS))

    def estop(self) -> None:
        """Latch the stop and call the robot's own ``estop()``, once per latch
        (the run loop passing the same press on does not repeat it).  Safe from
        any thread: the flag alone makes the run thread's next command a stop,
        so even if the lock is busy for a moment no further motion is
        commanded, and the run thread's own call then reaches the robot.
        Never raises.  A robot whose ``estop()`` is made for any thread
        (EstopsFromAnyThread: the boards' driver) is called at once, without
        the lock, which a read retrying on a lossy wire may hold."""
        self._estop.set()
        if self._estop_unlocked:
            if not self._estop_sent:
                self._send_estop()
            return
        if self._lock.acquire(timeout=0.5):
            try:
                if not self._estop_sent:
                    self._send_estop()
            finally:
                self._lock.release()

    def _send_estop(self) -> None:
        # estop() never raises by the protocol; a robot that breaks it (a
        # lost link) must not take the console down with it: stop what can
        # be stopped, say so, and let the next press try the robot again.
        try:
            self.inner.estop()
        except Exception as exc:  # noqa: BLE001 - the key must always work
            with contextlib.suppress(Exception):
                self.inner.stop_all()
            self._state.set_status(severity="error", message=f"EMERGENCY STOP: the robot "
                                   f"did not confirm its e-stop: {exc}")
        else:
            self._estop_sent = True
        self.estop_tick = self.ticks
        self._state.on_command(dict(ZERO_SPEEDS))

    def clear(self) -> None:
        """Clear the robot's latch, then this one.  Raises what the robot's
        ``clear()`` raises (a lost link); the stop then stays latched."""
        with self._lock:
            self.inner.clear()
            self._estop_sent = False
            self._estop.clear()
            self.estop_tick = None

    def diagnostics(self) -> dict[str, object]:
        with self._lock:
            return self.inner.diagnostics()

    def identity(self) -> dict[str, dict[str, int]] | None:
        """The boards' serial numbers and uptimes (what a journal keeps), or
        None for a robot that has none (the simulation)."""
        from stairbot.run.runner import board_identity

        with self._lock:
            return board_identity(self.inner)

    def close(self) -> None:
        with self._lock:
            self.inner.close()


class _TruthRobot(Robot, HasTruth, Protocol):
    """A robot that knows its truth."""


class WatchedTruthRobot(WatchedRobot):
    """A WatchedRobot around a robot that knows its truth (HasTruth)."""

    inner: _TruthRobot

    def truth(self) -> Truth:
        with self._lock:
            return self.inner.truth()


def watch(inner: Robot, state: LiveState, lock: threading.RLock,
          scene: Callable[[], SceneView] | None = None,
          wall: Callable[[], float] = time.monotonic,
          top: Callable[[], TopPose | None] | None = None) -> WatchedRobot:
    """The robot watched, with the capabilities it has (truth passes through);
    ``scene`` and ``top`` take the side view and the pose seen from above
    after a read (at most every SCENE_PERIOD_S of wall time)."""
    cls = WatchedTruthRobot if isinstance(inner, HasTruth) else WatchedRobot
    return cls(inner, state, lock, scene, wall, top)


class PacedClock:
    """The session's clock, advanced under the robot lock and, for a simulation,
    paced to ``scale`` simulated seconds per wall second (None: as fast as it goes)."""

    def __init__(self, inner: Clock, lock: threading.RLock,
                 wall: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        self.inner = inner
        self._lock = lock
        self._wall = wall
        self._sleep = sleep
        self._scale: float | None = None
        self._anchor: tuple[float, float] | None = None

    def set_scale(self, scale: float | None) -> None:
        self._scale = scale
        self._anchor = None

    def now(self) -> float:
        with self._lock:
            return self.inner.now()

    def idle(self, dt: float) -> None:
        """Advance ``dt`` under the lock, unpaced: a simulation's time while no
        run goes on (:meth:`~stairbot.console.robot_holder.RobotHolder.poll`)."""
        with self._lock:
            self.inner.advance(dt)
        self._anchor = None

    def advance(self, dt: float) -> None:
        with self._lock:
            self.inner.advance(dt)
            sim_now = self.inner.now()
        scale = self._scale
        if scale is None:
            return
        wall_now = self._wall()
        if self._anchor is None:
            self._anchor = (sim_now, wall_now)
            return
        due = self._anchor[1] + (sim_now - self._anchor[0]) / scale
        if due - wall_now > 0:
            self._sleep(due - wall_now)
        elif wall_now - due > 0.5:  # fell behind (a slow machine): do not race to catch up
            self._anchor = (sim_now, wall_now)
