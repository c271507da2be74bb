"""The last :data:`WINDOW_S` seconds of robot time of the values the graphs
draw: the IMU's pitch, the distance sensors (the four every robot has, and
the side pair SSR/SSL when the reading carries it), the two lifts' turn
counters.  One row a reading, kept by the robot's clock: a reading no newer
than the last (an idle robot read again while its clock stands) adds
nothing, so when the readings stop, the graphs stop too."""

from __future__ import annotations

import math
from collections import deque

from stairbot.hardware import SIDE_SENSORS, MotorId, SensorId, SensorStatus, Snapshot

WINDOW_S = 30.0
"""Robot seconds the graphs look back."""

COLUMNS: tuple[str, ...] = ("pitch", *(s.value for s in SensorId), MotorId.MTF.value,
                            MotorId.MTB.value)
"""The columns after the time: pitch (deg), SFR, SFL, SBR, SBL, SSR, SSL (m),
MTF, MTB (turns)."""
SIDE_SERIES: tuple[str, ...] = tuple(s.value for s in SIDE_SENSORS)
SERIES: tuple[str, ...] = tuple(c for c in COLUMNS if c not in SIDE_SERIES)
"""The series every robot has: the columns but the side pair's."""

NOT_CARRIED = math.inf
"""A sensor's value where the reading does not carry it (the side pair on a
snapshot without it): never drawn, shown as none.  (nan: a reading in ERROR.)"""

Row = tuple[float, ...]
"""(time_s, then one value per :data:`COLUMNS`; nan: none at that reading,
NOT_CARRIED: a sensor the reading does not have)."""


def series(side_pair: bool) -> tuple[str, ...]:
    """The series the graphs draw for a robot with (or without) the side pair."""
    return COLUMNS if side_pair else SERIES


def column(name: str) -> int:
    """Where the series ``name`` is in a Row."""
    return COLUMNS.index(name) + 1


def row_of(snap: Snapshot) -> Row:
    """The values the graphs keep of one reading (nan where there is none: no
    IMU, a sensor in ERROR, whose distance means nothing, a motor not read;
    NOT_CARRIED for a sensor the snapshot does not carry)."""
    values: list[float] = [snap.time_s, snap.imu.pitch_deg if snap.imu is not None else math.nan]
    for sensor in SensorId:
        r = snap.sensors.get(sensor)
        values.append(NOT_CARRIED if r is None else
                      math.nan if r.status is SensorStatus.ERROR else r.distance_m)
    for motor in (MotorId.MTF, MotorId.MTB):
        m = snap.motors.get(motor)
        values.append(math.nan if m is None else m.turns)
    return tuple(values)


class History:
    """Rows over the last ``window_s`` robot seconds (not thread-safe: the
    live state holds its lock around every call)."""

    def __init__(self, window_s: float = WINDOW_S) -> None:
        self.window_s = window_s
        self._rows: deque[Row] = deque()
        self._snaps: deque[Snapshot] = deque()
        """The readings the rows came from, row for row: the plots (key v,
        console/plotting.py) read any signal out of them."""

    def add(self, snap: Snapshot) -> None:
        """Keep ``snap``'s values if it is newer than the last; a clock that
        went back (another robot, a replay sought back) starts afresh."""
        rows = self._rows
        if rows:
            last = rows[-1][0]
            if snap.time_s == last:
                return
            if snap.time_s < last:
                self.clear()
        rows.append(row_of(snap))
        self._snaps.append(snap)
        start = snap.time_s - self.window_s
        while rows[0][0] < start:
            rows.popleft()
            self._snaps.popleft()

    def clear(self) -> None:
        self._rows.clear()
        self._snaps.clear()

    def rows(self) -> tuple[Row, ...]:
        return tuple(self._rows)

    def readings(self) -> tuple[Snapshot, ...]:
        """The readings kept, oldest first, one a row."""
        return tuple(self._snaps)
