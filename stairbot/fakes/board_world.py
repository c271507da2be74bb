"""The world behind both fake boards, and its pacing.

:class:`BoardWorld` is any Robot and Clock -- in practice the simulation's
SimRobot and SimClock, so the fake boards drive the same physics as
``sim://`` -- read at most once per instant.  In lockstep it advances only on
StepTo; otherwise a :class:`Pacer` advances it as wall time passes, for the
serial and the CAN server alike.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

from stairbot.drivers import messages as m
from stairbot.errors import HardwareError
from stairbot.fakes import sim_messages as sim
from stairbot.hardware import Clock, HasTruth, MotorId, Robot, Snapshot

if TYPE_CHECKING:
    from stairbot.fakes.boards import Board


class BoardWorld:
    """The robot behind both boards, read at most once per instant (so the
    sensor noise draws are the same as a ``sim://`` run's), and its clock.

    In lockstep the world advances only on :meth:`step_to`; otherwise the
    server calls :meth:`advance` as wall time passes.  ``side_pair``: the
    robot has the side pair SSR/SSL (its config's ``[sensors] side_model``),
    so the sensor board has six channels."""

    def __init__(self, robot: Robot, clock: Clock, lockstep: bool = False,
                 side_pair: bool = False) -> None:
        self.robot = robot
        self.clock = clock
        self.lockstep = lockstep
        self.side_pair = side_pair
        self.failure: str | None = None
        self._snap: Snapshot | None = None
        self._snap_time = -1.0
        self._time_us = round(clock.now() * 1e6)
        self._speeds: dict[MotorId, float] = {mid: 0.0 for mid in m.MOTOR_CHANNELS}

    def now(self) -> float:
        return self.clock.now()

    def snapshot(self) -> Snapshot | None:
        """The robot now, or None once the world has failed (see ``failure``)."""
        if self.failure is not None:
            return self._snap
        t = self.clock.now()
        if self._snap is None or t != self._snap_time:
            try:
                self._snap = self.robot.read()
            except HardwareError as exc:
                self._fail(str(exc))
                return self._snap
            self._snap_time = t
        return self._snap

    def _fail(self, reason: str) -> None:
        self.failure = reason
        self.robot.stop_all()

    def set_speeds(self, speeds: dict[MotorId, float]) -> None:
        self._speeds.update(speeds)
        if self.failure is None:
            self.robot.command(dict(self._speeds))

    def speeds(self) -> dict[MotorId, float]:
        return dict(self._speeds)

    def step_to(self, time_us: int) -> int:
        """Advance to ``time_us`` (no-op if already there or past); the time now."""
        if time_us > self._time_us and self.failure is None:
            self.advance((time_us - self._time_us) / 1e6)
            self._time_us = time_us
        return self._time_us

    def advance(self, seconds: float) -> None:
        if self.failure is not None:
            return
        try:
            self.clock.advance(seconds)
        except HardwareError as exc:
            self._fail(str(exc))
        if not self.lockstep:
            self._time_us = round(self.clock.now() * 1e6)

    def truth(self) -> sim.Truth:
        """GetTruth's answer: the world's own truth (a robot without it, such
        as a test's stub, reports zeros), and a fall the world failed on."""
        fell, pitch, offset = False, 0.0, 0.0
        if isinstance(self.robot, HasTruth):
            t = self.robot.truth()
            fell, pitch, offset = t.fell, t.max_pitch_deg or 0.0, t.offset_m or 0.0
        fell = fell or (self.failure is not None and "fell" in self.failure.lower())
        return sim.Truth(
            1 if fell else 0,
            max(-32767, min(32767, round(pitch * 100))),
            max(-(2**31) + 1, min(2**31 - 1, round(offset * 1000))),
        )

class Pacer:
    """Keeps a world that is not in lockstep up with the wall clock times
    ``time_scale``, one ``step_s`` step per :meth:`step`, so that a server
    looks at its line between steps: one that fell behind answers the host
    before it catches up.  Shared by the serial and the CAN server.

    A server that was not scheduled for a while (a loaded machine) finds
    the world behind the wall clock.  It catches up at most ``MAX_LAG_S``
    of wall time; beyond that the world pauses: the rest is let go (counted
    in ``behind`` and ``behind_s``) rather than run in a rush.  Run in a
    rush, the boards' watchdogs would count time in which the host's frames
    were on the line, unread, and trip where a real board, whose clock and
    UART never stall, would have heard them.  A run whose boards fell behind
    was not a real-time run throughout; the servers report it on exit."""

    MAX_WAIT_S = 0.05  # the longest a server waits on its line before looking again
    MAX_LAG_S = 0.05  # the most wall time a world that fell behind catches up

    def __init__(self, world: BoardWorld, boards: Iterable[Board], time_scale: float = 1.0,
                 step_s: float = 0.005, monotonic: Callable[[], float] = time.monotonic
                 ) -> None:
        self.world = world
        self.boards = list(boards)
        self.time_scale = time_scale
        self.step_s = step_s
        self._monotonic = monotonic
        self._start: tuple[float, float] | None = None  # (wall, world) at the first step
        self.behind = 0  # times the world fell more than MAX_LAG_S behind and paused
        self.behind_s = 0.0  # wall seconds let go in all

    def step(self) -> float:
        """Advance the world one step if it is due (and let every board check
        its watchdog and Moves); the seconds the server may then wait on its
        line: 0 after a step, until the next step is due otherwise, and
        MAX_WAIT_S in lockstep (only StepTo advances the world)."""
        if self.world.lockstep:
            return self.MAX_WAIT_S
        if self._start is None:
            self._start = (self._monotonic(), self.world.now())
        wall0, world0 = self._start
        wall = self._monotonic()
        due = world0 + (wall - wall0) * self.time_scale
        lag_s = (due - self.world.now()) / self.time_scale  # in wall time
        if lag_s > self.MAX_LAG_S + self.step_s / self.time_scale:
            let_go = lag_s - self.MAX_LAG_S
            self._start = (wall0 + let_go, world0)
            self.behind += 1
            self.behind_s += let_go
            due -= let_go * self.time_scale
        if self.world.now() + self.step_s <= due:
            self.world.advance(self.step_s)
            for board in self.boards:
                board.poll()
            return 0.0
        return min(self.MAX_WAIT_S, (self.world.now() + self.step_s - due) / self.time_scale)

    def report(self) -> str:
        """What a server's exit line adds: '' while the world kept up."""
        if not self.behind:
            return ""
        return (f", fell behind real time {self.behind} time(s), {self.behind_s:.2f} s let go "
                f"(the world paused meanwhile)")
