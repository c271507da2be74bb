"""The ``stairbot`` command: headless runs, the robot config, scenarios.

Exit codes (every subcommand):

* 0  the run ended as the scenario's ``[expect]`` says (or the command worked)
* 1  the run ended otherwise (the mismatching fields are named), or on a
     fault: a lost link, a failing board, a record or journal the disk
     refused (the robot is stopped first; one line on stderr)
* 2  bad input: config, scenario, robot URL, options; one line on stderr
* 130  interrupted with Ctrl-C (the robot is stopped first)

This module is the parser and the dispatch; ``run`` is :mod:`stairbot.cli.run`,
the commands that show inputs :mod:`stairbot.cli.show`, ``clear``
:mod:`stairbot.cli.clear`.  The subcommands ``console`` and ``fake-boards``
live in their own subpackages and are imported only when used, so
``stairbot run`` never loads textual.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Sequence
from importlib import import_module

from stairbot import __version__
from stairbot.args import bounded
from stairbot.cli.common import EXIT_INPUT, EXIT_INTERRUPTED, EXIT_MISMATCH, EXIT_OK, PROG
from stairbot.cli.run import cmd_run
from stairbot.cli.show import cmd_config_show, cmd_scenario_check, cmd_scenario_list
from stairbot.errors import InputError, OutputError, ReadFault
from stairbot.run.robots import TIME_SCALE_MAX, TIME_SCALE_MIN

# Subcommands that other subpackages implement: name -> ("module:function", help).
# The function takes the remaining argv (list[str]) and returns an exit code.
EXTERNAL: dict[str, tuple[str, str]] = {
    "console": ("stairbot.console.cli:main",
                "the operator console: a terminal UI that watches and commands the robot"),
    "fake-boards": ("stairbot.fakes.boards_cli:main",
                    "serve simulated motor and sensor boards on a pseudo-terminal or CAN bus"),
    "clear": ("stairbot.cli.clear:main",
              "show the boards' latches (emergency stop, tripped watchdog) and clear "
              "them once you confirm"),
    "sweep": ("stairbot.sweep.cli:main",
              "run many generated cases and judge each (stairbot sweep SPEC.toml; "
              "docs/envelope.md)"),
    "replay": ("stairbot.console.replay_cli:main",
               "play a recording (--record FILE.mcap, or JSON lines) in the console: "
               "play/pause, speed, seek; no robot is connected"),
    "plot": ("stairbot.recording.cli:main",
             "draw a recording (--record FILE.mcap or JSON lines) over time as a PNG "
             "(needs the extra stairbot[plot])"),
}

FOXGLOVE_PORT = 8765
"""``--foxglove`` alone: Foxglove's own default port (stairbot.recording.live,
which this module does not import: it loads the Foxglove SDK)."""

ROBOT_HELP = ("robot URL: sim:// (the simulation, default), serial://PORT?baud=N, "
              "can://INTERFACE/CHANNEL?bitrate=N")
SCENARIO_HELP = ("scenario TOML file, or the name of a shipped scenario (see "
                 "`stairbot scenario list`); default: five residential steps")
CONFIG_HELP = ("robot config TOML file, or a shipped robot's name (reference, ideal, sonar, ir, "
               "heavy_middle, landings); default: the reference robot")
RUN_CONFIG_HELP = CONFIG_HELP.replace("default: ", "default: the robot the scenario names "
                                      "(its `robot` key), else ")


class _Formatter(argparse.RawDescriptionHelpFormatter):
    """Keep the descriptions' line breaks and show defaults where they help."""


def build_parser() -> argparse.ArgumentParser:
    """The whole command line, every subcommand with its --help."""
    p = argparse.ArgumentParser(
        prog=PROG, formatter_class=_Formatter,
        description="Host software for a three-segment stair-climbing robot.",
        epilog="Exit codes: 0 as expected, 1 not as expected, 2 bad input, "
               "130 interrupted.\nSee `stairbot COMMAND --help` and README.md.",
    )
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", required=True)

    r = sub.add_parser(
        "run", formatter_class=_Formatter,
        help="run the robot headless: calibrate, climb, descend, summarise",
        description="Run the whole program (calibration, ascent, descent) on a robot,\n"
                    "headless.  Prints each phase change as one line, then a summary.\n"
                    "Exit 0 when the run ends as the scenario's [expect] says (without\n"
                    "[expect]: when it completes), 1 when it does not, 2 on bad input.",
    )
    r.add_argument("--robot", metavar="URL", default="sim://", help=ROBOT_HELP)
    r.add_argument("--scenario", metavar="FILE|NAME", help=SCENARIO_HELP)
    r.add_argument("--config", metavar="FILE", help=RUN_CONFIG_HELP)
    r.add_argument("--json", action="store_true",
                   help="print one JSON object (the result) on stdout; progress goes to stderr")
    r.add_argument("--realtime", action="store_true",
                   help="pace a simulated robot to the wall clock (default: as fast as possible)")
    r.add_argument("--time-scale", metavar="X", type=_time_scale,
                   help="pace a simulated robot at X simulated seconds per wall second "
                        f"({TIME_SCALE_MIN:g} to {TIME_SCALE_MAX:g})")
    r.add_argument("--record", metavar="FILE",
                   help="record the run to FILE: FILE.mcap as MCAP (every tick: pose, "
                        "motors, sensors, link; phases and events; for Foxglove), any "
                        "other name the event stream, one JSON object a line")
    r.add_argument("--foxglove", metavar="[HOST:]PORT", nargs="?", const=str(FOXGLOVE_PORT),
                   help="show the run live in Foxglove: foxglove-sdk's WebSocket server with "
                        "the topics of the MCAP record (docs/recording.md), stopped when the "
                        f"run ends; alone: 127.0.0.1:{FOXGLOVE_PORT}; PORT 0: any free port.  "
                        "HOST is 127.0.0.1 unless given: only this machine can connect.  A "
                        "simulation is paced to the wall clock unless --time-scale is given")
    r.add_argument("--calibrate-only", action="store_true",
                   help="only square up to the first riser (calibration), then stop; "
                        "[expect] is not checked: exit 0 when calibration completes")
    r.add_argument("--from-top", action="store_true",
                   help="the robot stands on the top of a flight it has not climbed, "
                        "facing away from it: back down it to the floor (continuous "
                        "descent; a scenario with start.on = 'top' implies it)")
    r.add_argument("-q", "--quiet", action="store_true",
                   help="print no progress lines, only the summary (or the JSON)")
    r.add_argument("--journal", metavar="FILE",
                   help="where the run's journal goes (every tick, durable: what --resume "
                        "reads); default for boards: $XDG_STATE_HOME/stairbot/journal-"
                        "<robot>.jsonl; a simulation keeps none unless given")
    r.add_argument("--resume", action="store_true",
                   help="carry on the run the journal says a host left unfinished: checks "
                        "the boards are the same and did not restart, says where the robot "
                        "believes it is, and asks before anything moves")
    r.add_argument("--yes", action="store_true",
                   help="answer yes for a headless run: let the robot limp home on the "
                        "sensors that remain if one is lost on the stairs (else it stays "
                        "stopped, lifts holding); with --resume: resume without asking (you "
                        "have looked at the robot)")
    r.add_argument("--discard-journal", action="store_true",
                   help="start a new run although the journal holds one that did not finish "
                        "(you have checked the robot stands at a start position again); the "
                        "old journal is kept, renamed beside it (JOURNAL.discarded.jsonl)")
    r.set_defaults(func=cmd_run)

    c = sub.add_parser("config", help="show the robot config and what follows from it",
                       description="Robot config commands.")
    csub = c.add_subparsers(dest="config_command", metavar="SUBCOMMAND", required=True)
    cs = csub.add_parser(
        "show", formatter_class=_Formatter,
        help="print the resolved config and its derived values",
        description="Print the resolved robot config: every section of the file and the\n"
                    "values derived from it (turn counts, max_step_rise_m, min_tread_m).",
    )
    cs.add_argument("--config", metavar="FILE", help=CONFIG_HELP)
    cs.add_argument("--json", action="store_true", help="print one JSON object instead of text")
    cs.set_defaults(func=cmd_config_show)

    s = sub.add_parser("scenario", help="check and list scenarios",
                       description="Scenario commands (the schema: docs/scenarios.md).")
    ssub = s.add_subparsers(dest="scenario_command", metavar="SUBCOMMAND", required=True)
    sc = ssub.add_parser("check", help="validate scenario files without running them",
                         description="Validate scenario files (or shipped names).  Exit 0 "
                                     "when all are valid, 2 when any is not.")
    sc.add_argument("files", nargs="+", metavar="FILE|NAME", help="scenario files or names")
    sc.set_defaults(func=cmd_scenario_check)
    sl = ssub.add_parser("list", help="list the shipped scenarios",
                         description="List the shipped scenarios: name and description.")
    sl.set_defaults(func=cmd_scenario_list)

    for name, (_target, text) in EXTERNAL.items():
        e = sub.add_parser(name, help=text, add_help=False, prefix_chars="\0",
                           description=text)
        e.add_argument("rest", nargs=argparse.REMAINDER)
        e.set_defaults(func=_external(name))
    return p


_time_scale = bounded(TIME_SCALE_MIN, TIME_SCALE_MAX)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code (the console script exits with it)."""
    args_list = list(sys.argv[1:] if argv is None else argv)
    if args_list and args_list[0] in EXTERNAL:  # the subcommand parses its own options
        return _external(args_list[0])(argparse.Namespace(rest=args_list[1:]))
    args = build_parser().parse_args(args_list)
    func: Callable[[argparse.Namespace], int] = args.func
    try:
        return func(args)
    except InputError as exc:
        return _input_error(exc)
    except (OutputError, ReadFault) as exc:  # before the robot moved (a run's own: cmd_run)
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return EXIT_MISMATCH
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # `stairbot run | head`: the reader left, nothing to say
        # (point stdout at /dev/null so the interpreter's final flush stays quiet)
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK


def _input_error(exc: Exception) -> int:
    print(f"{PROG}: error: {exc}", file=sys.stderr)
    return EXIT_INPUT


def _external(name: str) -> Callable[[argparse.Namespace], int]:
    def call(args: argparse.Namespace) -> int:
        target = EXTERNAL[name][0]
        module_name, _, attr = target.partition(":")
        try:
            func: Callable[[list[str]], int] = getattr(import_module(module_name), attr)
        except (ImportError, AttributeError) as exc:
            print(f"{PROG}: error: `{PROG} {name}` is not available in this build ({exc})",
                  file=sys.stderr)
            return EXIT_INPUT
        try:
            return func(list(args.rest))
        except InputError as exc:
            return _input_error(exc)
        except (OutputError, ReadFault) as exc:  # the disk refused a write or failed a read
            print(f"{PROG}: error: {exc}", file=sys.stderr)
            return EXIT_MISMATCH
        except KeyboardInterrupt:
            print(f"{PROG}: interrupted", file=sys.stderr)
            return EXIT_INTERRUPTED
    return call
