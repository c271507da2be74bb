"""``stairbot run``: open the robot, keep the journal (or resume from it),
run the program, record it, print the summary and judge the result against
the scenario's ``[expect]``."""

from __future__ import annotations

import argparse
import contextlib
import json
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, Any, TextIO

from stairbot.cli.common import EXIT_INPUT, EXIT_INTERRUPTED, EXIT_MISMATCH, EXIT_OK, PROG, ask
from stairbot.control.algorithm import limits
from stairbot.control.robot_config import config_for
from stairbot.errors import HardwareError, InputError, LatchedError, NoBoardError
from stairbot.events import Event, EventKind
from stairbot.inputs.config import RobotConfig, robot_shown
from stairbot.inputs.scenario import Scenario, expectation_mismatches, load_scenario
from stairbot.recording.record import EventRecord, RecordsTicks, open_record
from stairbot.run.paths import unused_path
from stairbot.text import printable

if TYPE_CHECKING:  # the Foxglove SDK loads only for --foxglove or a .mcap record
    from stairbot.recording.live import LiveServer


def _load_inputs(args: argparse.Namespace) -> tuple[RobotConfig, Scenario]:
    """The scenario, and the robot config: ``--config``, else the scenario's
    ``robot``, else the reference robot (a note on stderr when ``--config``
    overrides the scenario's robot with another)."""
    scenario = load_scenario(args.scenario)
    config, note = config_for(args.config, scenario)
    if note is not None:
        print(f"{PROG}: {note}", file=sys.stderr, flush=True)
    return config, scenario


def _live_server(text: str | None, config: RobotConfig,
                 url: str) -> contextlib.AbstractContextManager[LiveServer | None]:
    """``--foxglove [HOST:]PORT``: foxglove-sdk's WebSocket server for the
    run, said on stderr, stopped when the run ends (InputError when the
    address is bad or cannot be listened on: nothing is left running)."""
    if text is None:
        return contextlib.nullcontext()
    from stairbot.recording.live import serving

    return serving(text, config, url, lambda line: print(f"{PROG}: {line}", file=sys.stderr,
                                                    flush=True))


@contextmanager
def _record_file(path: str | None, config: RobotConfig,
                 live: LiveServer | None) -> Iterator[EventRecord | None]:
    """The run's record: MCAP for FILE.mcap (on the live server's channels,
    with ``--foxglove``), else JSON lines (InputError when it cannot be
    opened; a write the disk refuses raises OutputError once, then the
    record is silent and ``failed`` says why)."""
    if path is None:
        yield None
        return
    f = open_record(path, config, live.channels if live is not None else None)
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
    from stairbot.run.runner import RunControl, board_identity, run

    progress: TextIO = sys.stderr if args.json else sys.stdout
    # --foxglove: a simulation paced to the wall clock, to be watched, unless
    # --time-scale sets another pace
    realtime = args.realtime or (args.foxglove is not None and args.time_scale is None)
    options = RobotOptions(realtime=realtime, time_scale=args.time_scale,
                           allow_latched=args.resume)
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

    def keep_unfinished(path: Path | None) -> int | None:
        """A new run would write over the journal's unfinished run at
        ``path``: refused (EXIT_INPUT) unless --discard-journal, which sets it
        aside."""
        left = None if args.resume or path is None else unfinished(path)
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

    with _live_server(args.foxglove, config, args.robot) as live, \
            _record_file(unused_record(args.record), config, live) as record:
        feed = live.feed(record) if live is not None else None
        if realtime and not args.realtime and args.robot.startswith("sim:"):
            print(f"{PROG}: --foxglove: the simulation runs at the wall clock's pace, to be "
                  "watched (--time-scale X for another)", file=sys.stderr, flush=True)

        def sink(event: Event) -> None:
            if record is not None:  # OutputError (a full disk) ends the run
                record.write(event)
            if feed is not None:
                feed.write(event)
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
            kept = keep_unfinished(journal_path(args.robot, args.journal, exc.boards))
            if kept is not None:
                return kept
            print(f"{PROG}: error: cannot open {printable(args.robot)}: {exc}",
                  file=sys.stderr)
            return EXIT_MISMATCH
        except HardwareError as exc:
            print(f"{PROG}: error: cannot open {printable(args.robot)}: {exc}",
                  file=sys.stderr)
            return EXIT_MISMATCH
        # the robot's journal: by its motor board's serial number, once it answered
        path = journal_path(args.robot, args.journal, board_identity(session.robot))
        kept = keep_unfinished(path)
        if kept is not None:
            session.close()
            return kept
        controller = journal = None
        tap = None
        try:
            # every tick, and the pose: to an MCAP record (and the live server
            # on its channels), else to the live server alone
            ticking = record if isinstance(record, RecordsTicks) else feed
            if ticking is not None:
                from stairbot.recording.pose import pose_source

                ticking.watch(pose_source(session.sim, config, scenario), scenario, args.robot)
                tap = ticking.tick
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
            refusal = limits.narrow_steps_refusal(config)
            if refusal is not None:
                print(f"narrow_steps refused: {refusal}; treads down to "
                      f"min_tread_m = {limits.min_tread_m(config):.3f} m only", file=progress)
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
                             controller=controller, journal=journal, tap=tap,
                             limp_home=args.yes)
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
        _print_summary(data, scenario, args.robot, config.source, mismatches)
    if interrupted:
        print(f"{PROG}: interrupted: emergency stop latched, every motor stopped", file=sys.stderr)
        return EXIT_INTERRUPTED
    if result.awaits_consent:
        print(f"{PROG}: {_how_to_consent(args.robot, args.journal)}",
              file=sys.stderr)
    if mismatches:
        print(f"{PROG}: the run did not end as {printable(scenario.source)} expects: "
              + printable("; ".join(mismatches)), file=sys.stderr)
        return EXIT_MISMATCH
    return EXIT_OK


def _how_to_consent(url: str, journal: str | None) -> str:
    """How the operator consents to the limp home a run ended waiting for:
    boards carry the run on from its journal; a simulated robot ends with its
    run, so only a new run consents (before it starts)."""
    if url.startswith("sim:"):
        return ("the robot could limp home on the sensors that remain: a simulated run "
                f"ends here; `{PROG} run --yes` consents before a run")
    given = f" --journal {journal}" if journal else ""
    return printable(f"the robot can limp home on the sensors that remain: "
                     f"`{PROG} run --robot {url}{given} --resume --yes` carries this run on "
                     "home from its journal")


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


def _margins_line(m: dict[str, Any]) -> str:
    """The least margins of the run (docs/envelope.md, "Margins"); the
    physical ones only where the robot can tell them."""
    mm = {k: f"{m[k] * 1000:.1f} mm" for k in ("stability_m", "edge_m", "stroke_m")
          if m.get(k) is not None}
    parts = [f"{name} {mm[key]}" for name, key in (("stability", "stability_m"),
                                                   ("edge", "edge_m"), ("stroke", "stroke_m"))
             if key in mm]
    if m.get("pitch_deg") is not None:
        parts.append(f"pitch {m['pitch_deg']:.1f} deg")
    parts.append(f"sensor holds {m['sensor_holds']}")
    return "  least margins     " + ", ".join(parts)


def _print_summary(d: dict[str, Any], scenario: Scenario, robot: str, config: str,
                   mismatches: list[str]) -> None:
    rtf = d.get("realtime_factor")
    lines = [
        "",
        f"summary ({scenario.name} on {robot})",
        f"  robot config      {robot_shown(config)}",
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
        *([_margins_line(d["margins"])] if isinstance(d.get("margins"), dict) else []),
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
