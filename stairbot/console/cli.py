"""``stairbot console [--robot URL] [--scenario FILE|NAME] [--config FILE]
[--record FILE] [--speed 1x|10x|max] [--serve [HOST:]PORT] [--foxglove
[HOST:]PORT]``: the operator console, in this terminal or (``--serve``) in a
browser; ``--foxglove`` shows its runs live in Foxglove
(stairbot/recording/live.py).  ``stairbot console
--replay FILE [--speed 1x|10x|max]`` plays a recording instead, as
``stairbot replay FILE`` does (console/replay_cli.py).

Bad input (config, scenario, an unknown URL scheme, an unwritable record file)
is found before the screen opens and raises InputError, which ``stairbot``
turns into one line on stderr and exit 2.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from contextlib import AbstractContextManager, nullcontext
from typing import TYPE_CHECKING
from urllib.parse import urlsplit

from stairbot.console.robot_holder import SPEEDS
from stairbot.console.serve import parse_bind, serve
from stairbot.control.robot_config import config_for
from stairbot.errors import InputError, RobotUrlError
from stairbot.files import LineFile
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import load_scenario
from stairbot.run.paths import unused_path
from stairbot.run.robots import known_schemes

if TYPE_CHECKING:  # the Foxglove SDK loads only for --foxglove (or an MCAP record)
    from stairbot.recording.live import LiveServer


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="stairbot console",
        description="The operator console: watch and command the robot in a terminal.\n"
                    "Keys: space EMERGENCY STOP (everywhere), c clear it, s start, k calibrate\n"
                    "only, p pause/resume, x stop, r reset the simulation, u robot URL,\n"
                    "o scenario, f simulation speed, w record, g graphs, l limp home (after\n"
                    "a degraded stop: it asks at the stop), q quit; ctrl+p lists all.\n"
                    "--replay FILE plays a recording instead (stairbot replay).",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--robot", metavar="URL", default="sim://",
                   help="robot URL: sim:// (default), serial://PORT?baud=N, "
                        "can://INTERFACE/CHANNEL?bitrate=N")
    p.add_argument("--scenario", metavar="FILE|NAME",
                   help="scenario TOML file or shipped scenario name (default stairs)")
    p.add_argument("--config", metavar="FILE",
                   help="robot config TOML file or shipped robot's name (default: the "
                        "scenario's robot, else the reference robot)")
    p.add_argument("--record", metavar="FILE",
                   help="record to FILE: FILE.mcap as MCAP (every tick and event, for "
                        "Foxglove), any other name the event stream, one JSON object a line")
    p.add_argument("--speed", choices=tuple(SPEEDS), default=None,
                   help="simulation speed: 1x real time (default), 10x, max; with "
                        "--replay the replay's speed (max: the fastest, 50x)")
    p.add_argument("--replay", metavar="FILE",
                   help="play a recording (FILE.mcap, or FILE.jsonl: events alone) instead "
                        "of opening a robot, as `stairbot replay FILE` does; no robot is "
                        "connected")
    p.add_argument("--serve", metavar="[HOST:]PORT",
                   help="serve the console to a web browser at http://HOST:PORT/ instead of "
                        "opening it here (needs the extra stairbot[serve]); each browser tab "
                        "runs a console of its own with the options above.  HOST is "
                        "127.0.0.1 unless given: only this machine can connect.  Give "
                        "0.0.0.0 (every interface) or another address of this machine only "
                        "to let other machines command the robot")
    p.add_argument("--foxglove", metavar="[HOST:]PORT", nargs="?", const="8765",
                   help="show the console's runs live in Foxglove: foxglove-sdk's WebSocket "
                        "server with the topics of the MCAP record, stopped when the console "
                        "ends; alone: 127.0.0.1:8765; PORT 0: any free port.  HOST is "
                        "127.0.0.1 unless given: only this machine can connect")
    return p


def _check_url(url: str) -> None:
    scheme = urlsplit(url).scheme if "://" in url else ""
    schemes = known_schemes()
    if scheme not in schemes:
        allowed = ", ".join(f"{s}://" for s in sorted(schemes))
        raise RobotUrlError(url, None, f"unknown scheme {scheme!r}; allowed: {allowed}")


def check_record(path: str) -> None:
    """InputError unless the record can be written where the console will
    put it (``path``, or beside it when a file is there: never over it).  A
    FIFO no process reads is refused here, not waited on; a file this check
    creates is removed again, so the console still finds the name free."""
    try:
        chosen = unused_path(path)
    except FileExistsError as exc:
        raise InputError(path, None, f"cannot write the record: {exc}") from None
    existed = os.path.lexists(chosen)
    LineFile(chosen, "the record", fresh=False).close()
    if not existed:
        os.unlink(chosen)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the console until the operator quits; returns the exit code.
    Raises InputError (exit 2 in ``stairbot``) for bad input."""
    args = build_parser().parse_args(list(argv) if argv is not None else None)
    if args.replay is not None:
        return _replay(args)
    if args.speed is None:
        args.speed = "1x"
    bind = parse_bind(args.serve) if args.serve is not None else None
    # a bad scenario or config fails here, not behind the screen
    config, note = config_for(args.config, load_scenario(args.scenario))
    if note is not None:
        print(f"stairbot console: {note}", file=sys.stderr, flush=True)
    _check_url(args.robot)
    if args.record:
        check_record(args.record)
    if bind is not None:
        if args.foxglove is not None:
            raise InputError("--foxglove", None, "each browser tab of --serve runs a console "
                             "of its own, and one port serves one: give --foxglove to a "
                             "console in a terminal")
        return serve(args, *bind)
    from stairbot.console.app import build_app  # textual loads only when the screen opens

    app = build_app(config, url=args.robot, scenario=args.scenario, record=args.record,
                    speed=args.speed)
    with live_server(args.foxglove, config, args.robot) as live:
        if live is not None:
            app.engine.live = live
            for line in live.lines():
                app.state.note(line, "warning" if line.startswith("warning") else "information")
        app.run()
    # Textual sets 1 when the app ended on an unhandled error (the engine
    # stopped the robot on the way out): not the exit of a clean quit.
    return app.return_code or 0


def live_server(text: str | None, config: RobotConfig,
                url: str) -> AbstractContextManager[LiveServer | None]:
    """``--foxglove [HOST:]PORT``: the live server for the console's runs,
    said on stderr (seen once the console ends), stopped when the console
    ends.  InputError when the address is bad or cannot be listened on: the
    screen never opens."""
    if text is None:
        return nullcontext()
    from stairbot.recording.live import serving

    return serving(text, config, url, lambda line: print(f"stairbot console: {line}",
                                                    file=sys.stderr, flush=True))


def _replay(args: argparse.Namespace) -> int:
    """``--replay FILE``: the recording played; the options that open or
    record a robot are refused (one line), not ignored."""
    from stairbot.console.replay_cli import LIVE_SPEEDS, replay

    given = [name for name, value in (("--robot", args.robot != "sim://"),
                                      ("--scenario", args.scenario), ("--config", args.config),
                                      ("--record", args.record), ("--serve", args.serve),
                                      ("--foxglove", args.foxglove))
             if value]
    if given:
        raise InputError("--replay", None, f"plays a recording: no robot is opened, so "
                         f"{', '.join(given)} cannot be given with it")
    return replay(args.replay, LIVE_SPEEDS[args.speed or "1x"])


console_main = main
