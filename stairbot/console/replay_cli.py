"""``stairbot replay FILE [--speed X] [--paused]``: a recording played back
in the console, with play/pause, speed and seek (console/replay_app.py).

FILE is an MCAP recording (``stairbot run --record FILE.mcap``, the
console's ``w`` or ``--record``; a run killed part way leaves one cut short,
which plays up to where it ends) or a JSON-lines record (events alone).

Bad input -- a missing file, a directory, a name that is neither .mcap nor
.jsonl, a file that is not the recording its name says, the MCAP reader not
installed -- raises InputError (one line, exit 2) before the screen opens;
a read the disk fails is one line and exit 1.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from stairbot.console.replay import SPEEDS
from stairbot.errors import InputError

SPEED_WORDS = {f"{s:g}": s for s in SPEEDS} | {f"{s:g}x": s for s in SPEEDS}
SPEED_WORDS_SHOWN = [f"{s:g}" for s in SPEEDS]
LIVE_SPEEDS = {"1x": 1.0, "10x": 10.0, "max": SPEEDS[-1]}
"""``stairbot console --replay FILE --speed S``: the console's own speed words."""


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="stairbot replay",
        description="Play a recording in the console: FILE.mcap (stairbot run --record\n"
                    "FILE.mcap, or the console's w) with the sensors, motors, picture,\n"
                    "phases and events as they were; a JSON-lines record (events alone)\n"
                    "as its event list and phases over time.  No robot is connected.\n"
                    "Keys: p play/pause, + - speed, left/right 1 s, shift+left/right 5 s,\n"
                    "Home/End, g graphs, ? help, q quit.  Needs the MCAP reader for .mcap:\n"
                    "pip install 'stairbot[replay]'.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("file", metavar="FILE", help="the recording: FILE.mcap or FILE.jsonl")
    p.add_argument("--speed", metavar="X", default="1", type=_speed,
                   help="the speed it starts at: " + ", ".join(SPEED_WORDS_SHOWN)
                        + " (default 1)")
    p.add_argument("--paused", action="store_true", help="open paused at the start")
    return p



def _speed(text: str) -> float:
    value = SPEED_WORDS.get(text.strip().lower().rstrip("×"))
    if value is None:
        raise argparse.ArgumentTypeError(
            f"{text!r}; allowed: {', '.join(SPEED_WORDS_SHOWN)} (times real time)")
    return value


_speed.__name__ = "speed"  # what argparse names when the type fails


def check_reader(path: str) -> None:
    """InputError unless the MCAP reader a .mcap file needs is installed."""
    if not path.lower().endswith(".mcap"):
        return
    for module in ("mcap", "mcap_protobuf"):
        try:
            __import__(module)
        except ImportError:
            raise InputError("stairbot replay", None, f"needs {module.replace('_', '-')} to "
                             "read MCAP, which is not installed: pip install "
                             "'stairbot[replay]'") from None


def replay(path: str, speed: float = 1.0, paused: bool = False) -> int:
    """Load ``path`` (bad input raises InputError), then play it until the
    operator quits; the exit code."""
    from stairbot.recording.replay_load import load_replay

    check_reader(path)
    source = load_replay(path)  # a ReadFault: the CLI's one line and exit 1
    from stairbot.console.replay_app import build_replay_app  # textual: once it opens

    app = build_replay_app(source, speed=speed, playing=not paused)
    app.run()
    return app.return_code or 0


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(list(argv) if argv is not None else None)
    return replay(args.file, args.speed, args.paused)

