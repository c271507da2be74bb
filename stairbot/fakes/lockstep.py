"""Fake boards in lockstep, seen from the host: a simulation over a wire.

A ``serial://...?lockstep=1`` or ``can://...?lockstep=1`` URL names fake
boards (``stairbot fake-boards --lockstep``) whose world advances only when
the host says so.  The drivers open such boards with :class:`LockstepRobot`,
which this module registers with them on import
(:func:`stairbot.drivers.board_session.register_lockstep`):
the board robot of ``stairbot.drivers`` plus what only a simulation has --

* :class:`LockstepClock`: ``advance(dt)`` sends the motor board StepTo (the
  simulation-only message of docs/protocol.md) and the world moves on;
* ``truth()`` (the HasTruth capability): GetTruth, the world's own account
  of a fall, its largest pitch and the robot's offset from its start;
* a failed world (Status fault SIMULATION) becomes RobotFellError when the
  truth says the robot fell.

Commands wait in the output buffer for the StepTo that carries them out, and
the StepDone is awaited by the next read (the boards handle frames in order,
so that read sees the stepped world): one write and one round trip a tick.
"""

from __future__ import annotations

import contextlib

from stairbot.drivers import messages as m
from stairbot.drivers.board_robot import BoardRobot, locked
from stairbot.drivers.board_session import register_lockstep
from stairbot.drivers.link import BoardLink, Reply, Request
from stairbot.errors import HardwareError, RobotFellError
from stairbot.events import EventSink, discard
from stairbot.fakes import sim_messages as sim
from stairbot.hardware import Truth


class LockstepClock:
    """The host's clock against lockstep fake boards: ``advance(dt)`` asks the
    motor board to step the world to the new time."""

    def __init__(self, robot: LockstepRobot) -> None:
        self._robot = robot
        self._us = 0

    def now(self) -> float:
        return self._us / 1e6

    def start_at(self, time_us: int) -> None:
        """Begin at the world's time (boards a host opens after another ran them)."""
        self._us = time_us

    def advance(self, dt: float) -> None:
        self._us += round(dt * 1e6)
        self._robot.step_to(self._us)


class LockstepRobot(BoardRobot):
    """Both fake boards in lockstep over one link: see the module docstring.
    Its watchdog counts simulated time, which stands still between ticks, but
    the boards count its lease in wall time: the keepalive renews the lease of
    a robot left idle (a console before its run, a resume that checks its
    journal, an operator asked to confirm)."""

    LOCKSTEP = True
    HOLD_COMMANDS = True
    PIPELINED_STEP = True  # False: each advance() waits for its StepDone

    def __init__(self, link: BoardLink, url: str, watchdog_ms: int = 250,
                 sink: EventSink = discard, allow_latched: bool = False,
                 side_pair: str | None = None) -> None:
        self._step: Request | None = None
        super().__init__(link, url, watchdog_ms, clock=LockstepClock(self), sink=sink,
                         allow_latched=allow_latched, side_pair=side_pair)
        # The world may have run before this host opened it (a resumed run):
        # the clock starts where the world stands (StepTo 0 steps nothing).
        (done,) = self._wait([self._request(m.Board.MOTOR, [sim.StepTo(0)])])
        self._check_step(done)
        step = done.messages[0]
        if isinstance(step, sim.StepDone) and isinstance(self.clock, LockstepClock):
            self.clock.start_at(step.time_us)

    @property
    def feed_s(self) -> float:
        """The lease alone sets the keepalive's pace: the watchdog counts the
        world's time, which stands still while the robot is idle."""
        return self.lease_ms / 4000

    @locked
    def step_to(self, time_us: int) -> None:
        """The world advances to ``time_us``.  Pipelined, the StepTo waits in
        the output buffer with the speeds before it, and the next read's
        requests carry all of them in one write (a pty write costs a context
        switch, the dearest part of a tick).  Otherwise waits here."""
        if self._step is not None:
            self._check_step(self._wait([self._step])[0])
        self._step = self._request(m.Board.MOTOR, [sim.StepTo(time_us)],
                                   send=not self.PIPELINED_STEP)
        if not self.PIPELINED_STEP:
            step, self._step = self._step, None
            self._check_step(self._wait([step])[0])

    def _collect(self, reads: list[Request]) -> list[Reply]:
        step, self._step = self._step, None
        if step is None:
            return self._wait(reads)
        done, *replies = self._wait([step, *reads])  # the world stepped before ReadAll
        self._check_step(done)
        if step.attempts > 1 or step.revived:
            # The StepTo was sent again: the first copy (or its StepDone) was
            # lost, and the boards may have answered the ReadAlls before the
            # world stepped -- the last tick's world, taken for this one's
            # (5 % of frames lost on CAN: the robot seemed to stand still a
            # tick, then leap two, and backed 13 mm too far at an edge).
            # Read again, now that StepDone says the world has stepped.
            replies = self._wait([self._request(r.board, list(r.messages)) for r in reads])
        return replies

    def _check_step(self, reply: Reply) -> None:
        if not reply.messages or not isinstance(reply.messages[0], sim.StepDone):
            raise HardwareError(f"the motor board refused StepTo: {reply.messages}")

    @locked
    def truth(self) -> Truth:
        """What the fake boards know of their world (GetTruth): whether the
        robot fell, the most it pitched, its offset from the start.  The wire
        carries no pitch now and no fall reason: those are None.
        HardwareError when the boards cannot answer (a lost link, closed)."""
        if self._closed:
            raise HardwareError(f"{self.url}: closed; the fake boards cannot be asked")
        (reply,) = self._wait([self._request(m.Board.MOTOR, [sim.GetTruth()])])
        truth = reply.messages[0] if reply.messages else None
        if not isinstance(truth, sim.Truth):
            raise HardwareError(f"the motor board answered GetTruth with {reply.messages}")
        return Truth(fell=bool(truth.flags & sim.FELL), fall_reason=None,
                     pitch_deg=None, max_pitch_deg=truth.max_pitch_cdeg / 100,
                     offset_m=truth.offset_mm / 1000)

    def _world_failed(self, board: m.Board) -> None:
        try:
            fell = self.truth().fell
        except HardwareError:
            fell = False
        if fell:
            raise RobotFellError("the simulated robot fell (reported by the fake boards)")
        super()._world_failed(board)

    @locked
    def diagnostics(self) -> dict[str, object]:
        """The board robot's, and the world's truth as sim:// reports it
        (``fell``, ``max_pitch_deg``, ``offset_m``) when the boards can tell."""
        out = super().diagnostics()
        out["lockstep"] = True
        with contextlib.suppress(HardwareError):
            t = self.truth()
            out.update(fell=t.fell, max_pitch_deg=t.max_pitch_deg, offset_m=t.offset_m)
        return out


register_lockstep(LockstepRobot)
