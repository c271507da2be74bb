"""``stairbot fake-boards``: serve the emulated motor and sensor boards.

    stairbot fake-boards --serial [--scenario FILE] [--config FILE]
                         [--time-scale X | --lockstep] [fault options]

opens a pseudo-terminal, prints its path (the line ``serial://PATH``, plus
``?lockstep=1`` when in lockstep) and serves both boards on it, backed by the
same physics world as ``sim://``, until interrupted.

    stairbot fake-boards --serial --firmware native|qemu [...]

serves the boards' C firmware (firmware/, built with make on first use:
Linux programs, or STM32F405 images in qemu-system-arm) instead of the
Python fakes, on the same pty and the same world
(``stairbot.fakes.firmware_boards``).

    stairbot fake-boards --can udp_multicast/GROUP[?port=P&lan=1] [...]

serves them on a CAN bus instead (``stairbot.fakes.can_boards.main``) and
prints the ``can://`` URL a host opens.  ``udp_multicast`` is kept on this
machine: bound to GROUP:PORT, the group joined on the loopback interface
(127.0.0.1), sent with TTL 0, IPv4 groups only; no other host can send the
boards frames.  ``?lan=1`` opens it to the network (python-can's socket on
0.0.0.0:PORT, TTL 1 unless ?hop_limit=N): then any host there can send them
frames.
"""

from __future__ import annotations

import argparse
import contextlib
import signal
import sys
from collections.abc import Callable
from importlib import import_module

from stairbot.args import bounded
from stairbot.control.robot_config import config_for
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import launch_serials, make_boards, serials_words
from stairbot.fakes.firmware_boards import KINDS, FirmwareBoardServer, build_firmware
from stairbot.fakes.registry import registered
from stairbot.fakes.serial_boards import PtyPair, SerialBoardServer, WireFaults
from stairbot.fakes.sim import SimClock, SimRobot, motor_limits
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, load_scenario
from stairbot.run.robots import TIME_SCALE_MAX, TIME_SCALE_MIN

_probability = bounded(0.0, 1.0, " (a probability)")


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="stairbot fake-boards", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    wire = p.add_mutually_exclusive_group(required=True)
    wire.add_argument("--serial", action="store_true", help="serve on a new pseudo-terminal")
    wire.add_argument("--can", metavar="INTERFACE/CHANNEL",
                      help="serve on a CAN bus, e.g. udp_multicast/239.74.163.2: on loopback "
                      "only (127.0.0.1, TTL 0) unless the URL adds ?lan=1")
    p.add_argument("--firmware", choices=KINDS, default=None,
                   help="serve the boards' C firmware (firmware/) on the pty instead of the "
                        "Python fakes, built with make: native = Linux programs; qemu = "
                        "STM32F405 images in qemu-system-arm (serial only)")
    p.add_argument("--scenario", help="scenario TOML file or shipped scenario name")
    p.add_argument("--config", help="robot config TOML file or shipped robot's name "
                   "(default: the scenario's robot, else the reference robot)")
    pace = p.add_mutually_exclusive_group()
    pace.add_argument("--time-scale", type=bounded(TIME_SCALE_MIN, TIME_SCALE_MAX),
                      default=1.0, metavar="X",
                      help="simulated seconds per wall second (default 1: real time; "
                           f"{TIME_SCALE_MIN:g} to {TIME_SCALE_MAX:g})")
    pace.add_argument("--lockstep", action="store_true",
                      help="advance the world only on the host's StepTo (host URL ?lockstep=1)")
    f = p.add_argument_group("fault injection on the wire (probabilities per frame)")
    f.add_argument("--drop", type=_probability, default=0.0)
    f.add_argument("--corrupt", type=_probability, default=0.0)
    f.add_argument("--duplicate", type=_probability, default=0.0)
    f.add_argument("--late", type=_probability, default=0.0)
    f.add_argument("--late-s", type=bounded(0.0001, 60.0, " s"), default=0.1,
                   help="delay of a late frame, s (at most 60)")
    f.add_argument("--silent-after", type=bounded(0.0, 86400.0, " s"), default=None,
                   metavar="S",
                   help="boards stop answering after S seconds of board time")
    f.add_argument("--silent-board", choices=("motor", "sensor"), default=None,
                   help="only this board goes silent")
    f.add_argument("--fault-seed", type=int, default=0)
    return p


def make_world(config: RobotConfig, scenario: Scenario, lockstep: bool) -> BoardWorld:
    """The simulated robot behind the fake boards (never paced by its clock:
    the server paces it)."""
    robot = SimRobot(config, scenario)
    return BoardWorld(robot, SimClock(robot, None), lockstep=lockstep,
                      side_pair=config.sensors.has_side_pair)


def faults_from(args: argparse.Namespace) -> WireFaults:
    board = {"motor": 1, "sensor": 2}.get(args.silent_board or "")
    return WireFaults(drop=args.drop, corrupt=args.corrupt, duplicate=args.duplicate,
                      late=args.late, late_s=args.late_s, silent_board=board,
                      silent_after_s=args.silent_after, seed=args.fault_seed)


def stop_on_signals(stop: Callable[[], None]) -> None:
    """SIGTERM calls ``stop``; Ctrl-C (SIGINT) raises KeyboardInterrupt and
    stops the boards, as their banner says, even when they were started with
    SIGINT ignored (a background job, a test runner's worker): Python keeps
    an inherited SIG_IGN, and `kill -INT` would do nothing.  Call it before
    the URL is printed: whoever reads it may signal at once.  Outside the
    main thread no handler can be set, and none is."""

    def on_term(_sig: int, _frame: object) -> None:
        stop()

    with contextlib.suppress(ValueError):  # not the main thread: no handler
        signal.signal(signal.SIGTERM, on_term)
        signal.signal(signal.SIGINT, signal.default_int_handler)


def main(argv: list[str]) -> int:
    """Run the subcommand; returns the exit code (InputError propagates to the
    CLI, which prints one line and exits 2)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.can is not None and args.firmware is not None:
        parser.error("--firmware serves the serial wire only: use --serial with it")
    if args.can is not None:
        can_main = import_module("stairbot.fakes.can_boards").main
        code: int = can_main(argv)
        return code
    scenario = load_scenario(args.scenario)
    config, note = config_for(args.config, scenario)
    if note is not None:
        print(f"stairbot fake-boards: {note}", file=sys.stderr, flush=True)
    world = make_world(config, scenario, args.lockstep)
    pty = PtyPair()
    serials = launch_serials()
    server: SerialBoardServer
    if args.firmware is not None:
        try:
            server = FirmwareBoardServer(pty.master, world, build_firmware(args.firmware),
                                         motor_limits(config), serials, faults_from(args),
                                         time_scale=args.time_scale, kind=args.firmware)
        except BaseException:
            pty.close()
            raise
        words = f"C firmware ({args.firmware}), motor board serial {serials[0]}, " \
                f"sensor board serial {serials[1]}"
    else:
        boards = make_boards(world, serials)
        server = SerialBoardServer(pty.master, world, boards, faults_from(args),
                                   time_scale=args.time_scale)
        words = serials_words(boards)
    stop_on_signals(server.stop)
    suffix = "?lockstep=1" if args.lockstep else (
        f"?time_scale={args.time_scale:g}" if args.time_scale != 1.0 else "")
    url = f"serial://{pty.path}{suffix}"
    print(url, flush=True)
    print(f"fake boards ({words}) serving on {pty.path} (Ctrl-C to stop)",
          file=sys.stderr, flush=True)
    try:
        with registered(url, wire="serial", scenario=scenario.name,
                        config=args.config or scenario.robot or "reference",
                        serials=words):
            server.serve()
    except KeyboardInterrupt:
        pass
    finally:
        pty.close()
        if isinstance(server, FirmwareBoardServer):
            for line in server.close():
                print(line, file=sys.stderr)
        s = server.stats
        print(f"fake boards: {s.frames_rx} frames in, {s.frames_tx} out, {s.crc_errors} CRC "
              f"errors, {s.malformed} malformed, {s.duplicates} repeats, {s.injected} faults "
              f"injected, {s.overflows} replies nobody read{server.pacer.report()}",
              file=sys.stderr)
    return 0


fake_boards_main = main

__all__ = ["build_parser", "fake_boards_main", "main", "make_world"]
