"""A still robot for pinning the console's layout: fixed readings and a fixed
picture (segment 1 lifted before the first riser), nothing time-dependent.
(A module of its own, not conftest.py: other test folders have a conftest.)"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from stairbot.console.app import StairbotConsole, build_app
from stairbot.control.robot_config import load_config
from stairbot.errors import LinkLostError
from stairbot.events import Event, EventKind
from stairbot.hardware import (
    Imu,
    MotorId,
    MotorState,
    Point,
    Scene,
    SensorId,
    SensorReading,
    Snapshot,
    Speeds,
)
from stairbot.inputs.scenario import load_scenario
from stairbot.run.robots import RobotSession
from stairbot.views.side_view import stairs_from_scenario

LIFT = 0.19  # segment 1 raised this far above segment 2, m


def _box(x0: float, x1: float, y0: float, y1: float) -> tuple[Point, ...]:
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))


class StillSim:
    """Just enough of stairbot.fakes.sim.SimRobot for the picture (HasScene)."""

    def scene(self) -> Scene:
        stairs = stairs_from_scenario(load_scenario(), 0.225)
        b, t = 0.016, 0.061
        return Scene(
            time_s=12.34,
            stairs=stairs,
            segments=(_box(-0.085, -0.01, b + LIFT, t + LIFT), _box(-0.16, -0.085, b, t),
                      _box(-0.235, -0.16, b, t)),
            wheels=((-0.0665, LIFT), (-0.0285, LIFT), (-0.1415, b), (-0.1035, b),
                    (-0.2165, b), (-0.1785, b)),
            wheel_radius=0.016, yaw_deg=0.0, lateral_m=0.0, fell=False,
        )


HEALTH = {"frames_per_s": 1480.5, "rtt_median_ms": 0.41, "rtt_p99_ms": 1.2, "crc_errors": 0.0,
          "lost": 0.0, "late": 1.0, "retries": 2.0, "frames_tx": 9000.0}


class StillRobot:
    def __init__(self, health: dict[str, float] | None = None) -> None:
        self.health = health or {}
        self.commands: list[dict[MotorId, float]] = []
        self.stops = 0
        self.estopped = False

    def read(self) -> Snapshot:
        sensors = {SensorId.SFR: SensorReading(0.265), SensorId.SFL: SensorReading(0.262),
                   SensorId.SBR: SensorReading(0.040), SensorId.SBL: SensorReading(0.047)}
        motors = {m: MotorState(4.97, 0.0) for m in
                  (MotorId.MWF, MotorId.MWB, MotorId.MWR, MotorId.MWL)}
        motors[MotorId.MTF] = MotorState(LIFT / 0.002, 10.0)
        motors[MotorId.MTB] = MotorState(0.0, 0.0)
        return Snapshot(12.34, sensors, motors, self.health, imu=Imu(0.0, 0.0))  # level

    def command(self, speeds: Speeds) -> None:
        self.commands.append(dict(speeds))

    def stop_all(self) -> None:
        self.stops += 1

    def estop(self) -> None:
        self.stops += 1
        self.estopped = True

    def clear(self) -> None:
        self.estopped = False

    def diagnostics(self) -> dict[str, object]:
        return {}

    def close(self) -> None:
        pass


class StillClock:
    def __init__(self) -> None:
        self.t = 12.34

    def now(self) -> float:
        return self.t

    def advance(self, dt: float) -> None:
        self.t += dt


def still_open(simulated: bool = True, wired: bool | None = None) -> Callable[..., RobotSession]:
    """``wired`` (default: not ``simulated``): no in-process world, link health;
    wired and simulated are fake boards."""
    on_wire = not simulated if wired is None else wired

    def open_fn(url: str, config: Any, scenario: Any, options: Any) -> RobotSession:
        return RobotSession(StillRobot(HEALTH if on_wire else None), StillClock(), url, simulated,
                            None if on_wire else StillSim())
    return open_fn


EVENTS = [
    Event(0.0, EventKind.PHASE, "calibration 1 — read the front sensors"),
    Event(0.02, EventKind.INFO, "case 3: SFR = SFL = 0.497 m"),
    Event(4.1, EventKind.PHASE, "ascent 1 — start"),
    Event(4.12, EventKind.PHASE, "ascent 2 — approach the riser"),
    Event(8.9, EventKind.PAUSE, "standing rule: SFR/SFL disagree (0.101 m / 0.112 m)"),
    Event(9.3, EventKind.RESUME, "standing rule: SFR/SFL agree again"),
    Event(10.2, EventKind.PHASE, "ascent 3 — lift segment 1"),
]


def show_climbing(app: StairbotConsole) -> None:
    """Put a mid-climb phase, context and events into the live state."""
    app.state.on_phase("ascent 3 — lift segment 1", "ascent",
                       {"number_of_steps": 2, "tab_length_to_edge": [0.143, 0.146] + [0.0] * 18},
                       "ascent_lift_first")
    for e in EVENTS:
        app.state.on_event(e)


def make_still_app(simulated: bool = True, wired: bool | None = None,
                   **kw: Any) -> StairbotConsole:
    """The console on a still robot (``simulated=False``: a wired one); the
    values' ages are pinned at 0 (a stopped clock) unless ``ages_wall`` is given."""
    kw.setdefault("ages_wall", lambda: 0.0)
    return build_app(load_config(), open_fn=still_open(simulated, wired), **kw)


class ScriptedRobot(StillRobot):
    """Reads whatever the test last put in ``snap``; ``silent``: answers no
    read (the console's idle poll then reads nothing)."""

    def __init__(self, first: Snapshot) -> None:
        super().__init__()
        self.snap = first
        self.silent = False

    def read(self) -> Snapshot:
        if self.silent:
            raise LinkLostError("link lost: no reply (the test's robot is silent)")
        return self.snap


def scripted_app(robot: ScriptedRobot, ages: list[float]) -> StairbotConsole:
    """The console on ``robot``, its values' ages by the wall clock ``ages[0]``."""
    def open_fn(url: str, config: Any, scenario: Any, options: Any) -> RobotSession:
        return RobotSession(robot, StillClock(), url, True, StillSim())

    return build_app(load_config(), open_fn=open_fn, ages_wall=lambda: ages[0])
