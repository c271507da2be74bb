"""The safety supervisor: checks the robot every tick, whatever the phase logic
believes, and names what is wrong.

It watches the robot's tilt (:mod:`stairbot.control.tilt`: the IMU's pitch, roll and
their rates against ``[safety]``, and an IMU that is declared but missing or
not a number; a stale one the controller holds on, as on a stale sensor),
and a stalled motor: one commanded to turn that does not (a wheel
against an obstacle, a jammed lift, a dead encoder).  Tipping on, or
grinding on, helps nothing and may break something: the program ends with an
error and every motor stops, lifts holding.

Pure Python, on the controller's clock (the snapshots' times).
"""

from __future__ import annotations

from dataclasses import dataclass

from stairbot.control.tilt import TiltWatch
from stairbot.hardware import LIFT_MOTORS, MotorId, Snapshot, Speeds
from stairbot.inputs.config import RobotConfig

STALL_S = 1.0
"""A motor that makes less than STALL_SHARE of its commanded motion for this
long, in controller time, has stalled."""
STALL_SHARE = 0.2
"""What share of the commanded motion counts as moving."""
MIN_COMMAND = 0.2
"""Commands below this share of the motor's top speed are not watched (a
motor creeping to its target may rightly barely move)."""


@dataclass
class _Watch:
    since_s: float
    start_turns: float
    expected: float = 0.0
    """Turns the commands since ``since_s`` asked for (signed)."""


class Supervisor:
    """One per controller: :meth:`check` each snapshot, then
    :meth:`commanded` with the speeds sent for it."""

    def __init__(self, cfg: RobotConfig) -> None:
        m = cfg.motors
        self._vmax = {mo: m.lift_speed if mo in LIFT_MOTORS else m.wheel_speed for mo in MotorId}
        self._watched = tuple((mo, MIN_COMMAND * v) for mo, v in self._vmax.items())
        """Each motor, and the least command watched on it."""
        self._watch: dict[MotorId, _Watch] = {}
        self._sent: Speeds = {}
        self._prev: Snapshot | None = None
        self.tilt = TiltWatch(cfg.safety)

    def commanded(self, speeds: Speeds) -> None:
        """The speeds sent after the last snapshot checked (they act until the next)."""
        self._sent = speeds

    def check(self, snap: Snapshot) -> str | None:
        """A reason to stop the robot now, or None: the tilt first (the robot
        tipping is the most urgent), then a stall."""
        return self.tilt.check(snap) or self._stall(snap)

    def _stall(self, snap: Snapshot) -> str | None:
        prev, self._prev = self._prev, snap
        if prev is None:
            return None
        dt = snap.time_s - prev.time_s
        sent, watch = self._sent, self._watch
        if dt <= 0.0:  # no time to judge a motor by: every stretch starts afresh
            watch.clear()
            return None
        for motor, least in self._watched:
            v = sent.get(motor, 0.0)
            if -least < v < least:
                if motor in watch:
                    del watch[motor]
                continue
            w = watch.get(motor)
            if w is None or (w.expected > 0) != (v > 0):
                w = self._watch[motor] = _Watch(prev.time_s, prev.turns(motor))
            w.expected += v * dt
            if snap.time_s - w.since_s < STALL_S:
                continue
            moved = snap.turns(motor) - w.start_turns
            if moved * (1 if v > 0 else -1) < STALL_SHARE * abs(w.expected):
                return (f"motor stall: {motor} was commanded {w.expected:+.2f} turns over "
                        f"{snap.time_s - w.since_s:.1f} s and made {moved:+.2f}: stopped "
                        "instead of grinding")
            del self._watch[motor]  # it moves: watch the next stretch afresh
        return None
