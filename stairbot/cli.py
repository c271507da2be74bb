"""The ``stairbot`` command: headless runs, the robot config, scenarios.

Exit codes (every subcommand):

* 0  the run ended as the scenario's ``[expect]`` says (or the command worked)
* 1  the run ended otherwise (the mismatching fields are named), or on a
     fault: a lost link, a failing board, a record or journal the disk
     refused (the robot is stopped first; one line on stderr)
* 2  bad input: config, scenario, robot URL, options; one line on stderr
* 130  interrupted with Ctrl-C (the robot is stopped first)

The subcommands ``console`` and ``fake-boards`` live in their own subpackages
and are imported only when used, so ``stairbot run`` never loads textual.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import replace
from importlib import import_module
from types import FrameType
from typing import Any, TextIO

from stairbot import __version__
from stairbot.cli_show import (
    EXIT_INPUT,
    EXIT_OK,
    PROG,
    ask,
    cmd_config_show,
    cmd_scenario_check,
    cmd_scenario_list,
)
from stairbot.errors import (
    HardwareError,
    InputError,
    LatchedError,
    NoBoardError,
    OutputError,
    ReadFault,
)
from stairbot.events import Event, EventKind
from stairbot.inputs.config import RobotConfig, load_config
from stairbot.inputs.scenario import (
    Scenario,
    expectation_mismatches,
    load_scenario,
)
from stairbot.recording.record import EventRecord, RecordsTicks, open_record
from stairbot.run.paths import unused_path
from stairbot.run.robots import TIME_SCALE_MAX, TIME_SCALE_MIN
from stairbot.text import printable

EXIT_MISMATCH, EXIT_INTERRUPTED = 1, 130

# Subcommands that other subpackages implement: name -> ("module:function", help).
# The function takes the remaining argv (list[str]) and returns an exit code.
EXTERNAL: dict[str, tuple[str, str]] = {
    "console": ("stairbot.console.cli:main",
                "the operator console: a terminal UI that watches and commands the robot"),
    "fake-boards": ("stairbot.fakes.boards_cli:main",
                    "serve simulated motor and sensor boards on a pseudo-terminal or CAN bus"),
    "clear": ("stairbot.cli_clear:main",
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

ROBOT_HELP = ("robot URL: sim:// (the simulation, default), serial://PORT?baud=N, "
              "can://INTERFACE/CHANNEL?bitrate=N")
SCENARIO_HELP = ("scenario TOML file, or the name of a shipped scenario (see "
                 "`stairbot scenario list`); default: five residential steps")
CONFIG_HELP = ("robot config TOML file, or a shipped robot's name (reference, ideal, sonar, ir, "
               "heavy_middle); default: the reference robot")


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
    r.add_argument("--config", metavar="FILE", help=CONFIG_HELP)
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
                   help="with --resume: resume without asking (you have looked at the robot)")
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


def bounded(lo: float, hi: float, unit: str = "") -> Callable[[str], float]:
    """An argparse type: a number from ``lo`` to ``hi`` (finite; nan and inf
    are refused), the message naming the value and the bounds."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
        if not lo <= value <= hi:  # nan fails too
            raise argparse.ArgumentTypeError(
                f"{text!r} is out of range; allowed: {lo:g} to {hi:g}{unit}")
        return value
    parse.__name__ = "number"  # what argparse says when the type fails
    return parse


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


# -- run ---------------------------------------------------------------------------


def _load_inputs(args: argparse.Namespace) -> tuple[RobotConfig, Scenario]:
    return load_config(args.config), load_scenario(args.scenario)


@contextmanager
def _record_file(path: str | None, config: RobotConfig) -> Iterator[EventRecord | None]:
    """The run's record: MCAP for FILE.mcap, else JSON lines (InputError when
    it cannot be opened; a write the disk refuses raises OutputError once,
    then the record is silent and ``failed`` says why)."""
    if path is None:
        yield None
        return
    f = open_record(path, config)
    try:
        yield f
    finally:
        f.close()


def unused_record(path: str | None) -> str | None:
    """Where the event record goes: ``path``, or beside it under a name not
    taken (``name-1.jsonl``) when a recording is already there -- a record
    never overwrites one -- saying so on stderr.  InputError when every
    such name is taken."""
    if path is None:
        return None
    try:
        chosen = unused_path(path)
    except FileExistsError as exc:
        raise InputError(path, None, f"cannot write the record: {exc}") from None
    if chosen != path:
        print(f"{PROG}: {printable(path)} exists (not overwritten): recording to "
              f"{printable(chosen)}",
              file=sys.stderr, flush=True)
    return chosen


@contextmanager
def _ctrl_c_stops(request_stop: Callable[[str], None],
                  estop: Callable[[], None]) -> Iterator[None]:
    """First Ctrl-C latches the emergency stop at once (from a thread of its
    own: the robot's ``estop()`` does not wait for a read in progress) and
    asks the run loop to end cleanly; a second one raises KeyboardInterrupt
    at once (the loop's finally still stops the robot)."""
    pressed = False

    def handler(_sig: int, _frame: FrameType | None) -> None:
        nonlocal pressed
        if pressed:
            raise KeyboardInterrupt
        pressed = True
        threading.Thread(target=estop, name="Ctrl-C emergency stop", daemon=True).start()
        request_stop("interrupted by Ctrl-C: emergency stop latched")

    try:
        previous = signal.signal(signal.SIGINT, handler)
    except ValueError:  # not the main thread: leave Ctrl-C as it is
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def cmd_run(args: argparse.Namespace) -> int:
    """``stairbot run``: open the robot, run the program, summarise, judge."""
    config, scenario = _load_inputs(args)
    # Imported here: the runner pulls in the controller, which `config show` needs not.
    from stairbot.control.algorithm.phases import Mode
    from stairbot.run.journaled import (
        NotConfirmed,
        journal_path,
        set_aside,
        start_journal,
        unfinished,
    )
    from stairbot.run.journaled import resume as resume_run
    from stairbot.run.resume import ResumeRefused
    from stairbot.run.robots import RobotOptions, open_robot
    from stairbot.run.runner import RunControl, run

    progress: TextIO = sys.stderr if args.json else sys.stdout
    options = RobotOptions(realtime=args.realtime, time_scale=args.time_scale,
                           allow_latched=args.resume)
    path = journal_path(args.robot, args.journal)
    from_top = args.from_top or scenario.start.on == "top"
    if args.calibrate_only and from_top:
        print(f"{PROG}: error: --calibrate-only squares up to a riser ahead; a robot on the "
              "top of a flight (--from-top, or start.on = 'top') has none: leave one out",
              file=sys.stderr)
        return EXIT_INPUT
    if args.from_top and args.robot.startswith("sim:") and scenario.start.on != "top":
        print(f"{PROG}: error: --from-top: the simulated robot stands where "
              f"{printable(scenario.source)} puts it, on the floor; give a scenario with "
              "start.on = 'top' (it implies --from-top), e.g. --scenario top_descent",
              file=sys.stderr)
        return EXIT_INPUT
    mode = Mode.CALIBRATE_ONLY if args.calibrate_only else \
        Mode.DESCEND if from_top else Mode.FULL
    if args.resume and args.discard_journal:
        print(f"{PROG}: error: --resume carries the journal's run on, --discard-journal sets "
              "it aside: leave one out", file=sys.stderr)
        return EXIT_INPUT
    left = None if args.resume or path is None else unfinished(path)

    def keep_unfinished() -> int | None:
        """A new run would write over the journal's unfinished run: refused
        (EXIT_INPUT) unless --discard-journal, which sets it aside."""
        if left is None or path is None:
            return None
        if not args.discard_journal:
            print(f"{PROG}: error: {path} holds {left}: carry it on with `{PROG} run --robot "
                  f"{args.robot} --resume`; or, once the robot stands at a start position "
                  f"again, `{PROG} clear --robot {args.robot}` (if the boards hold latches) "
                  "and run again with --discard-journal (the journal is kept, renamed)",
                  file=sys.stderr)
            return EXIT_INPUT
        aside = set_aside(path)
        print(f"{PROG}: the journal of the run that did not finish is kept as {aside}",
              file=sys.stderr, flush=True)
        return None

    with _record_file(unused_record(args.record), config) as record:
        def sink(event: Event) -> None:
            if record is not None:  # OutputError (a full disk) ends the run
                record.write(event)
            if not args.quiet and event.kind is not EventKind.SUMMARY:
                print(printable(event.line()), file=progress, flush=True)

        # The robot is opened before the journal is looked at: a journal whose
        # run another stairbot is driving now is in use, not unfinished.
        try:
            session = open_robot(args.robot, config, replace(options, world=scenario))
        except NoBoardError as exc:  # the URL was fine; the message names board and URL
            print(f"{PROG}: error: {exc}", file=sys.stderr)
            return EXIT_MISMATCH
        except LatchedError as exc:  # after a host that stopped mid-run: --resume first
            kept = keep_unfinished()
            if kept is not None:
                return kept
            print(f"{PROG}: error: cannot open {printable(args.robot)}: {exc}",
                  file=sys.stderr)
            return EXIT_MISMATCH
        except HardwareError as exc:
            print(f"{PROG}: error: cannot open {printable(args.robot)}: {exc}",
                  file=sys.stderr)
            return EXIT_MISMATCH
        kept = keep_unfinished()
        if kept is not None:
            session.close()
            return kept
        controller = journal = None
        tap = None
        try:
            if isinstance(record, RecordsTicks):  # MCAP: every tick, and the pose
                from stairbot.recording.pose import pose_source

                record.watch(pose_source(session.sim, config, scenario), scenario, args.robot)
                tap = record.tick
            if args.resume:
                resumed = resume_run(path, args.robot, session, config, sink, yes=args.yes,
                                     out=progress, confirm=ask)
                controller, journal = resumed.controller, resumed.journal
            else:
                journal = start_journal(path, args.robot, session, config, scenario.name, mode)
        except NotConfirmed as exc:
            session.close()
            print(f"{PROG}: error: {exc}", file=sys.stderr)
            return EXIT_INPUT
        except ResumeRefused as exc:
            session.close()
            print(f"{PROG}: error: cannot resume: {exc}", file=sys.stderr)
            return EXIT_MISMATCH
        except HardwareError as exc:  # the boards did not confirm the resume's Clear
            session.close()
            print(f"{PROG}: error: cannot resume: {exc}", file=sys.stderr)
            return EXIT_MISMATCH
        except BaseException:
            session.close()
            raise
        if not args.quiet:
            if config.narrow_steps_refusal is not None:
                print(f"narrow_steps refused: {config.narrow_steps_refusal}; treads down to "
                      f"min_tread_m = {config.min_tread_m:.3f} m only", file=progress)
            what = f" ({scenario.description})" if scenario.description else ""
            verb = "resuming" if args.resume else "running"
            line = (f"{verb} {scenario.name}{what} on {args.robot}"
                    + (", calibration only" if args.calibrate_only else "")
                    + (", down from the top" if from_top else "")
                    + (f"; journal {path}" if journal is not None else ""))
            print(printable(line), file=progress, flush=True)
        control = RunControl()
        link: object = None
        try:
            with _ctrl_c_stops(control.request_stop, session.robot.estop):
                result = run(session, config, sink=sink, mode=mode, control=control,
                             controller=controller, journal=journal, tap=tap)
        except KeyboardInterrupt:
            session.robot.estop()
            session.robot.stop_all()
            print(f"{PROG}: interrupted: emergency stop latched", file=sys.stderr)
            return EXIT_INTERRUPTED
        finally:
            with contextlib.suppress(Exception):  # a summary extra, never a reason to fail
                link = session.robot.diagnostics().get("link")
            session.close()
            if journal is not None:
                journal.close()
        refused = (record.failed if record is not None else None) or (
            journal.failed if journal is not None else None)
    if refused is not None:  # the run ended on it: the robot is stopped
        print(f"{PROG}: error: {refused}; the run stopped, every motor stopped",
              file=sys.stderr)
        return EXIT_MISMATCH
    data = result.to_dict()
    if isinstance(link, dict):  # a robot on a wire: what its link counted
        data["link"] = link
    interrupted = control.stop_reason is not None
    if interrupted:
        mismatches = ["interrupted: not judged"]
    elif args.calibrate_only:
        mismatches = [] if result.outcome == "completed" else [
            f"outcome: expected 'completed', got {result.outcome!r}"]
    else:
        mismatches = expectation_mismatches(scenario.expect, data)
    if args.json:
        out = {**data, "robot": args.robot, "scenario": scenario.name,
               "config": config.source, "interrupted": interrupted,
               "as_expected": not mismatches, "mismatches": mismatches}
        print(json.dumps(out, sort_keys=True))
    else:
        _print_summary(data, scenario, args.robot, mismatches)
    if interrupted:
        print(f"{PROG}: interrupted: emergency stop latched, every motor stopped", file=sys.stderr)
        return EXIT_INTERRUPTED
    if mismatches:
        print(f"{PROG}: the run did not end as {printable(scenario.source)} expects: "
              + printable("; ".join(mismatches)), file=sys.stderr)
        return EXIT_MISMATCH
    return EXIT_OK


def _fmt(value: Any, unit: str = "", digits: int = 3) -> str:
    if value is None:
        return "n/a"
    if isinstance(value, float):
        return f"{value:.{digits}f}{unit}"
    return f"{value}{unit}"


def _link_line(link: dict[str, Any]) -> str:
    keys = ("frames_tx", "frames_rx", "retries", "revived", "feeds", "lost", "late", "stray",
            "duplicates", "crc_errors", "error_frames", "foreign")
    return "  link              " + ", ".join(
        f"{k.replace('_', ' ')} {link[k]:g}" for k in keys if k in link)


def _print_summary(d: dict[str, Any], scenario: Scenario, robot: str,
                   mismatches: list[str]) -> None:
    rtf = d.get("realtime_factor")
    lines = [
        "",
        f"summary ({scenario.name} on {robot})",
        f"  outcome           {d['outcome']}"
        + (f" (ascent ended: {d['ascent_end']})" if d.get("ascent_end") else ""),
        f"  steps             climbed {d['steps_climbed']}, descended {d['steps_descended']}",
        f"  pauses            {d['pauses']}",
        f"  error             {d['error'] or 'none'}",
        *([f"  ended             {d['reason']}"]
          if d.get("reason") and not d.get("error") else []),
        f"  fell              {'yes' if d['fell'] else 'no'}"
        f" (max pitch {_fmt(d.get('max_pitch_deg'), ' deg', 1)})",
        f"  offset from start {_fmt(d.get('final_offset_m'), ' m')}",
        *([f"  touched a wall    {d['wall_contact']}"] if d.get("wall_contact") else []),
        "  tilt              " + ("watched (IMU)" if d.get("tilt_watched")
                                  else "NOT watched: the robot config declares no IMU"),
        f"  time              {_fmt(d['sim_time_s'], ' s', 2)} robot time, "
        f"{_fmt(d['wall_time_s'], ' s', 2)} wall"
        + (f" (realtime x{rtf:.0f})" if isinstance(rtf, float | int) else ""),
        *([_link_line(d["link"])] if isinstance(d.get("link"), dict) else []),
        "  expected          " + ("yes" if not mismatches else "; ".join(mismatches)
                                    if mismatches[0].startswith("interrupted")
                                    else "NO: " + "; ".join(mismatches)),
    ]
    print("\n".join(printable(line) for line in lines), flush=True)
