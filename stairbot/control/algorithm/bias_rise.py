"""The rise below each tread as each back sensor read it on the way up: evidence
:class:`~stairbot.control.algorithm.bias.BiasWatch` judges a back sensor on in
descent 2 (not in the seed, which has no sensor faults).

Ascent 7 lifts segment 3 beside the riser until MTB's counter is back at 0:
segment 3 then hangs level with segment 2 over the floor below the step,
its sensors reading BACK_CLEARANCE + the rise.  Descent 2 of the same step
starts from the same pose on the other side of the riser (MTB at 0, segments
1 and 2 on the tread, segment 3 over the drop) and lowers segment 3: a
sensor that reads right then reads what it read at the end of that step's
ascent 7, less MTB's travel since.  A sensor that went wrong after that
(a bias or a stuck value as descent 1 or 2 moves it over the edge: no
mount height and no onset name it) no longer does, while its partner
still does.

:class:`Rises` keeps, for each step climbed, each sensor's reading less
MTB's travel (``lift_travel_per_turn`` a turn, counted at the time the
filtered reading stands for: :func:`~stairbot.control.algorithm.edge_measure.edge_lag_s`
ago) over the last RECORD_TICKS ticks of ascent 7 -- only where the two
agreed within the pair tolerance there (a pair that disagreed already has
one wrong, and nothing says which) -- and, while the standing rule stands
in descent 2, the same for the wait's last second.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

from stairbot.control.algorithm.phases import Phase
from stairbot.control.timeline import keep_since, value_at
from stairbot.control.tolerances import pair_tolerance
from stairbot.hardware import MotorId, SensorId, SensorStatus, Snapshot
from stairbot.inputs.config import RobotConfig

RECORD_TICKS = 25
"""The rise is each sensor's mean over the last this many ticks of ascent 7
(0.5 s at the 20 ms tick): the lift slows to a stop there, and over half a
second the sensors' noise averages down (a reading at 0.2 m is the noisiest
the back pair gives on the way up)."""
STAND_TICKS = 50
"""While the standing rule waits in descent 2, each sensor's reading is the
mean of its last this many ticks (the wait's last second, as the rule's
own median)."""


_LIFT_THIRD, _LOWER_THIRD = Phase.ASCENT_LIFT_THIRD, Phase.DESCENT_LOWER_THIRD
"""Bound once: an enum member's look-up costs, every tick."""


@dataclass(frozen=True, slots=True)
class Rise:
    """Step ``step`` (0-based)'s rise as the back pair read it at the end of
    its ascent 7: each sensor's reading at MTB's 0, m (BACK_CLEARANCE + the
    rise, when it reads right)."""

    step: int
    right_m: float
    left_m: float


class Rises:
    """Each climbed step's :class:`Rise`, and the back pair's means while the
    standing rule waits in descent 2 (module docstring)."""

    __slots__ = ("_cfg", "_lag", "_lift_m", "_mtb", "_ascent", "_stand", "rises")

    def __init__(self, cfg: RobotConfig) -> None:
        from stairbot.control.algorithm.edge_measure import edge_lag_s

        self._cfg = cfg
        self._lag = edge_lag_s(cfg)
        self._lift_m = cfg.motors.lift_travel_per_turn
        self._mtb: list[tuple[float, float]] = []
        self._ascent: deque[tuple[float, float]] = deque(maxlen=RECORD_TICKS)
        self._stand: deque[tuple[float, float]] = deque(maxlen=STAND_TICKS)
        self.rises: dict[int, Rise] = {}

    def _at_zero(self, snap: Snapshot) -> tuple[float, float] | None:
        """SBR's and SBL's readings less MTB's travel from 0 at the time they
        stand for (None: either gives no distance)."""
        r, left = snap.sensors[SensorId.SBR], snap.sensors[SensorId.SBL]
        if r.status is not SensorStatus.OK or left.status is not SensorStatus.OK:
            return None
        now = snap.time_s
        self._mtb.append((now, snap.turns(MotorId.MTB)))
        then = now - self._lag
        keep_since(self._mtb, then)
        lowered = -value_at(self._mtb, then) * self._lift_m
        return r.distance_m + lowered, left.distance_m + lowered

    def tick(self, snap: Snapshot, where: Phase, paused: bool, steps: int) -> None:
        """One tick in ``where`` (the phase, or the one the standing rule
        stopped in, ``paused``); ``steps``: the steps climbed so far."""
        if where is _LIFT_THIRD and not paused:
            at = self._at_zero(snap)
            if at is not None:
                self._ascent.append(at)
            return
        if self._ascent:
            # ascent 7 just ended; the step counts once it ended as the seed says
            if where is Phase.ASCENT_CHECK and len(self._ascent) == RECORD_TICKS:
                right = sum(a[0] for a in self._ascent) / RECORD_TICKS
                left = sum(a[1] for a in self._ascent) / RECORD_TICKS
                if abs(left - right) <= pair_tolerance(self._cfg, min(right, left), back=True):
                    self.rises[steps - 1] = Rise(steps - 1, right, left)
            self._ascent.clear()
        if where is _LOWER_THIRD and paused:
            at = self._at_zero(snap)
            if at is not None:
                self._stand.append(at)
        elif self._stand or self._mtb:
            self._stand.clear()
            self._mtb.clear()

    def standing(self) -> tuple[float, float] | None:
        """SBR's and SBL's readings at MTB's 0, the means over the standing
        rule's wait's last second in descent 2 (None: not that many yet)."""
        n = len(self._stand)
        if n < STAND_TICKS:
            return None
        return (sum(a[0] for a in self._stand) / n, sum(a[1] for a in self._stand) / n)


def by_rise(cfg: RobotConfig, rise: Rise, standing: tuple[float, float], disagree: float,
            match: float, off_by: float) -> tuple[SensorId, float, float] | None:
    """At the end of the standing rule's wait in descent 2: the back sensor
    that no longer reads the rise it read on the way up (less MTB's travel
    since), by ``off_by`` or more, as the pair's disagreement (left − right,
    ``disagree``) says within ``match``, while its partner reads it within
    half a pair tolerance (two sigmas of one tick's difference; both figures
    are means of many ticks).  Returns the sensor, its offset and its
    partner's, or None."""
    offs = {SensorId.SBR: standing[0] - rise.right_m, SensorId.SBL: standing[1] - rise.left_m}
    within = pair_tolerance(cfg, min(standing), back=True) / 2
    for sensor, partner in ((SensorId.SBL, SensorId.SBR), (SensorId.SBR, SensorId.SBL)):
        off, p_off = offs[sensor], offs[partner]
        said = disagree if sensor is SensorId.SBL else -disagree
        if abs(p_off) <= within and abs(off) >= off_by and abs(off - p_off - said) <= match:
            return sensor, off, p_off
    return None
