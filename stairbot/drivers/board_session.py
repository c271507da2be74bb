"""Opening the boards on a link as a robot session: the real boards'
:class:`~stairbot.drivers.board_robot.BoardRobot`, or, for fake boards in
lockstep (``lockstep=1``), the robot the fakes register here
(:func:`register_lockstep`; ``stairbot.fakes.lockstep`` does on import, and
the URL dispatcher :mod:`stairbot.run.robots` loads it for a lockstep URL).
The drivers never import the fakes."""

from __future__ import annotations

from typing import Protocol

from stairbot.drivers.board_robot import BoardRobot
from stairbot.drivers.link import BoardLink
from stairbot.errors import RobotUrlError
from stairbot.inputs.config import RobotConfig
from stairbot.run.robots import RobotSession


class LockstepOpener(Protocol):
    """What opens fake boards in lockstep as a robot (the fakes' LockstepRobot)."""

    def __call__(self, link: BoardLink, url: str, watchdog_ms: int, *,
                 allow_latched: bool, side_pair: str | None) -> BoardRobot: ...


_lockstep: LockstepOpener | None = None


def register_lockstep(opener: LockstepOpener) -> None:
    """The robot that opens fake boards in lockstep (the fakes call this)."""
    global _lockstep
    _lockstep = opener


def wanted_side_pair(config: RobotConfig) -> str | None:
    """Where ``config`` gives the robot the side pair, for messages
    (``robot.toml: [sensors] side_model = "ir"``); None when it has none."""
    if not config.sensors.has_side_pair:
        return None
    return f'{config.source}: [sensors] side_model = "{config.sensors.side_model}"'


def open_board_session(link: BoardLink, url: str, *, watchdog_ms: int, lockstep: bool,
                       time_scale: float, allow_latched: bool = False,
                       side_pair: str | None = None) -> RobotSession:
    """The session of the boards on ``link`` (closed again if they cannot be
    opened).  Fake boards in lockstep (``lockstep``) are opened by the
    robot the fakes registered (:func:`register_lockstep`): their clock
    steps their world; RobotUrlError when none is.  Boards that
    hold a latch raise LatchedError unless ``allow_latched``; a sensor board
    without the side pair ``side_pair`` names (``wanted_side_pair``) raises
    BoardMismatchError."""
    robot: BoardRobot
    try:
        if lockstep:
            if _lockstep is None:
                raise RobotUrlError(url, "lockstep", "simulation only: no lockstep robot is "
                                    "registered (stairbot.fakes.lockstep registers it; "
                                    "stairbot.run.robots.open_robot loads it for such a URL)")
            robot = _lockstep(link, url, watchdog_ms, allow_latched=allow_latched,
                              side_pair=side_pair)
        else:
            robot = BoardRobot(link, url, watchdog_ms, time_scale=time_scale,
                               allow_latched=allow_latched, side_pair=side_pair)
    except BaseException:
        link.close()
        raise
    return RobotSession(robot=robot, clock=robot.clock, url=url, simulated=robot.simulated)
