"""``stairbot clear``: show the latches the boards hold and, once the
operator confirms, clear them.

A board latches its emergency stop (a press of the console's key, Ctrl-C, a
run that ended in an error) and its watchdog when it trips (frames stopped
coming while it was armed: the host crashed, hung or lost the wire mid-run).
Opening the boards never clears a latch: ``stairbot run`` and the console
refuse boards that hold one, naming this command.  The operator looks at the
robot first -- it may stand half way up a step -- and then confirms.
Clearing leaves the run journal as it is: a run a killed host left
unfinished can still be carried on (``stairbot run --resume``), and this
command says so when the robot's journal holds one.

Exit 0: nothing latched, or cleared; 1: the boards could not be reached or
did not confirm the clear; 2: bad input, or no confirmation.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

from stairbot.cli.common import EXIT_INPUT, EXIT_OK, PROG, ask
from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.drivers.board_robot import BoardRobot
from stairbot.drivers.handshake import latch_names
from stairbot.errors import HardwareError
from stairbot.run.robots import RobotOptions, RobotSession, open_robot

EXIT_FAILED = 1


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=f"{PROG} clear", formatter_class=argparse.RawDescriptionHelpFormatter,
        description=__doc__.split("\n\n", 1)[0] + "\n\n" + __doc__.split("\n\n", 1)[1])
    p.add_argument("--robot", metavar="URL", required=True,
                   help="the boards: serial://PORT?... or can://INTERFACE/CHANNEL?...")
    p.add_argument("--yes", action="store_true",
                   help="clear without asking (you have looked at the robot); without it "
                        "the command asks on the terminal, and refuses when there is none")
    return p


def _say_unfinished(url: str, session: RobotSession) -> None:
    """Say so when the robot's journal holds a run that did not finish."""
    from stairbot.run.journaled import session_journal, unfinished

    path = session_journal(session)
    left = None if path is None else unfinished(path)
    if left is not None:
        print(f"{url}: the journal {path} holds {left}; clearing keeps it: "
              f"`{PROG} run --robot {url} --resume` carries it on")


def main(argv: list[str], confirm: Callable[[str], bool] = ask) -> int:
    args = build_parser().parse_args(argv)
    if not args.robot.startswith(("serial://", "can://")):
        print(f"{PROG} clear: {args.robot} holds no latch that outlives a run "
              "(only boards on serial:// or can:// do): nothing to clear", file=sys.stderr)
        return EXIT_OK
    try:
        session = open_robot(args.robot, load_config(), RobotOptions(allow_latched=True))
    except HardwareError as exc:
        print(f"{PROG}: error: cannot open {args.robot}: {exc}", file=sys.stderr)
        return EXIT_FAILED
    robot = session.robot
    try:
        assert isinstance(robot, BoardRobot)
        if not robot.latched:
            print(f"{args.robot}: no board holds a latch: nothing to clear")
            return EXIT_OK
        for board, flags in sorted(robot.latched.items()):
            print(f"{args.robot}: the {m.Board(board).name.lower()} board has "
                  f"{latch_names(flags, robot.status[board].fault)}")
        _say_unfinished(args.robot, session)
        question = ("Look at the robot first: it may stand part way up a step, and the next "
                    "run starts from where it stands.  Clear these latches? [y/N] ")
        if not args.yes and not confirm(question):
            print(f"{PROG}: error: not cleared: no confirmation "
                  "(answer y on a terminal, or add --yes)", file=sys.stderr)
            return EXIT_INPUT
        try:
            robot.clear(m.ClearMask.ALL)
        except HardwareError as exc:
            print(f"{PROG}: error: the boards did not confirm the clear: {exc}",
                  file=sys.stderr)
            return EXIT_FAILED
        print(f"{args.robot}: cleared")
        return EXIT_OK
    finally:
        session.close()
