"""The tilt watch: the supervisor's check of the IMU, every tick.

The robot stops -- every motor, the lifts holding -- when segment 2's pitch
or roll is beyond the config's limit (``[safety] max_pitch_deg``,
``max_roll_deg``), or turning faster than ``max_rate_dps``: well before the
robot tips over, and whatever the phase believes.  When in doubt it stops as
well: a robot whose config declares an IMU (``[safety] imu = true``) and
whose snapshot has none, or one that is not a number, cannot be watched
(:meth:`TiltWatch.check`: the program ends).  An IMU reading older than
``imu_max_age_s`` cannot be watched either (:meth:`TiltWatch.stale`): the
controller treats it as it treats a stale distance sensor -- every motor
stops at once, the lifts hold, the timers stand, and the run goes on only
when a fresh reading comes back within the sensor wait (the program ends
otherwise).  One reply delayed on the wire then costs a pause of a tick or
two, not the run; the robot never moves on an IMU reading older than the
limit.  A robot declared without an IMU is not watched at all, and
:attr:`TiltWatch.watched` says so (the run tells it).

Pure Python, on the controller's clock (the snapshots' times).
"""

from __future__ import annotations

import math

from stairbot.hardware import Imu, Snapshot
from stairbot.inputs.sections import Safety

STOPPED = "every motor stopped, lifts holding"
_INF = math.inf


class TiltWatch:
    """Checks each snapshot's IMU against ``[safety]``; one per supervisor."""

    def __init__(self, safety: Safety) -> None:
        self.safety = safety

    @property
    def watched(self) -> bool:
        """Whether tilt is watched at all (the config declares an IMU)."""
        return self.safety.imu

    def describe(self) -> str:
        """What is watched, in words, for the operator at the start of a run."""
        s = self.safety
        if not s.imu:
            return "tilt not watched: the robot config declares no IMU ([safety] imu = false)"
        return (f"tilt watched: the robot stops beyond pitch ±{s.max_pitch_deg:g}°, roll "
                f"±{s.max_roll_deg:g}° or {s.max_rate_dps:g}°/s, or without an IMU reading "
                f"newer than {s.imu_max_age_s:g} s")

    def check(self, snap: Snapshot) -> str | None:
        """A reason to end the run and stop the robot now, or None.  An IMU
        reading's age is not looked at here (:meth:`stale`); a stale reading
        beyond a limit is still a reason: the robot was there."""
        s = self.safety
        if not s.imu:
            return None
        imu = snap.imu
        if imu is not None and abs(imu.pitch_deg) <= s.max_pitch_deg \
                and abs(imu.roll_deg) <= s.max_roll_deg \
                and abs(imu.pitch_rate_dps) <= s.max_rate_dps \
                and abs(imu.roll_rate_dps) <= s.max_rate_dps and -_INF < imu.age_s < _INF:
            return None  # every tick of a normal run: nothing more to look at (NaN fails it)
        if imu is None:
            return ("IMU missing: the robot config declares one ([safety] imu = true) but the "
                    f"robot reports none, so tilt cannot be watched: {STOPPED}")
        if not _finite(imu):
            return (f"IMU error: it reports pitch {imu.pitch_deg}°, roll {imu.roll_deg}°, "
                    f"rates {imu.pitch_rate_dps}/{imu.roll_rate_dps}°/s, age {imu.age_s} s: "
                    f"{STOPPED}")
        for name, value, limit, unit, sides in (
            ("pitch", imu.pitch_deg, s.max_pitch_deg, "°", ("nose up", "nose down")),
            ("roll", imu.roll_deg, s.max_roll_deg, "°", ("right side down", "left side down")),
            ("pitch rate", imu.pitch_rate_dps, s.max_rate_dps, "°/s", ("nose up", "nose down")),
            ("roll rate", imu.roll_rate_dps, s.max_rate_dps, "°/s",
             ("right side down", "left side down")),
        ):
            if abs(value) > limit:
                side = sides[0] if value > 0 else sides[1]
                return (f"tilt: segment 2's {name} is {value:+.1f}{unit} ({side}), beyond the "
                        f"limit ±{limit:g}{unit}: {STOPPED}")
        return None


    def stale(self, snap: Snapshot) -> str | None:
        """Why tilt cannot be watched on this snapshot's IMU reading, older
        than ``imu_max_age_s`` (a reason to hold, not to end: the module
        header), or None.  A missing or broken IMU is :meth:`check`'s."""
        s, imu = self.safety, snap.imu
        if not s.imu or imu is None or not imu.age_s > s.imu_max_age_s:
            return None
        return (f"IMU stale (tilt cannot be watched): its reading is {imu.age_s:.3f} s old "
                f"(limit {s.imu_max_age_s:g} s)")


def _finite(imu: Imu) -> bool:
    return all(math.isfinite(v) for v in
               (imu.pitch_deg, imu.roll_deg, imu.pitch_rate_dps, imu.roll_rate_dps, imu.age_s))
