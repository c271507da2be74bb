"""Run one case in-process: what every executor (process pool, Dask) calls.

Never raises: a crash of the program itself becomes verdict ``error`` with its
traceback, so one bad case never stops a sweep.
"""

from __future__ import annotations

import signal
import time
import traceback
from typing import Any

from stairbot.sweep.cases import Case
from stairbot.sweep.verdict import judge


def ignore_sigint() -> None:
    """Pool initializer: Ctrl-C goes to the parent, which stops cleanly and
    lets the running cases finish; workers must not die mid-case."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


STILL = 0.02
"""A motor turning slower than this share of its rated speed is standing: a
simulated wheel settles with micro-motion (about 0.1 % of rated) after a stop."""
SETTLE_TICKS = 5


AFTER_S = 2.0
"""How long the simulation runs on after the run ended, every motor stopped,
to see the robot stay where it stopped: one that the tilt supervisor
stopped past its support goes on tipping, and may fall half a second
later, after the run has ended and been judged "fell: no"."""


def _left_moving(session: Any, config: Any) -> list[str]:
    """The motors still turning five ticks after the run ended (a reading taken
    with no time passed would repeat the last snapshot, from before the stop).
    A robot that fell cannot be read: :func:`_fell_after` tells it."""
    from stairbot.errors import HardwareError
    from stairbot.hardware import MotorId

    lifts = (MotorId.MTF, MotorId.MTB)
    for _ in range(SETTLE_TICKS):
        session.clock.advance(config.algorithm.tick)
    try:
        motors = session.robot.read().motors
    except HardwareError:
        return []
    return sorted(str(m) for m, state in motors.items() if abs(state.speed_tps) > STILL * (
        config.motors.lift_speed if m in lifts else config.motors.wheel_speed))


def _fell_after(session: Any, config: Any) -> str | None:
    """Why the robot fell in the AFTER_S after the run (None: it stood)."""
    from stairbot.errors import RobotFellError

    tick = config.algorithm.tick
    for _ in range(round(AFTER_S / tick)):
        try:
            session.robot.read()
        except RobotFellError as exc:
            return str(exc)
        session.clock.advance(tick)
    return None


def run_case(case: Case) -> dict[str, Any]:
    """Run ``case`` on ``sim://`` and judge it.  Returns the JSONL record."""
    wall0, cpu0 = time.perf_counter(), time.process_time()
    record: dict[str, Any] = {"case": case.index, "axes": case.axes, "facts": case.facts}
    try:
        from stairbot.control.algorithm.phases import Mode
        from stairbot.control.robot_config import load_config, parse_config
        from stairbot.inputs.scenario import parse_scenario
        from stairbot.run.robots import RobotOptions, open_robot
        from stairbot.run.runner import run

        scenario = parse_scenario(case.scenario_text, f"<case {case.index}>")
        config = (load_config() if case.config_text is None
                  else parse_config(case.config_text, f"<case {case.index} config>"))
        session = open_robot("sim://", config, RobotOptions(world=scenario))
        try:
            # headless, with the operator's consent to limp home (stairbot run --yes)
            result = run(session, config, mode=Mode.for_start(scenario.start.on),
                         limp_home=True)
            moving = _left_moving(session, config)
            fell_after = None if result.fell else _fell_after(session, config)
        finally:
            session.close()
        data = result.to_dict()
        if fell_after is not None:
            data.update(fell=True, fell_after=fell_after)
        verdict, why = judge(data, case.facts, moving)
        record.update(verdict=verdict, why=why, result=data)
    except Exception as exc:  # noqa: BLE001 - any crash is this case's verdict
        record.update(verdict="error", why=f"{type(exc).__name__}: {exc}",
                      traceback=traceback.format_exc(), result=None)
    record["wall_s"] = round(time.perf_counter() - wall0, 3)
    record["cpu_s"] = round(time.process_time() - cpu0, 3)
    return record
