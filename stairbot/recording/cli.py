"""``stairbot plot FILE [-o OUT.png]``: a recording (MCAP or JSON lines)
drawn over time as a PNG.

Bad input -- a missing file, one that is not a recording, an empty one,
an output that cannot be written, matplotlib not installed -- raises
InputError, which ``stairbot`` turns into one line on stderr and exit 2; a
read the disk fails is one line and exit 1.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

from stairbot.files import LineFile, shown


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="stairbot plot",
        description="Draw a recording (stairbot run --record FILE.mcap, or a JSON-lines\n"
                    "record) over time as a PNG: the phases as bands, the pitch, the\n"
                    "segments' heights, the lifts' extensions, the sensors' readings with\n"
                    "their status.  A JSON-lines record holds events alone: its plot has\n"
                    "the phases and the events.  Needs matplotlib: pip install "
                    "'stairbot[plot]'.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("file", metavar="FILE", help="the recording (.mcap or JSON lines)")
    p.add_argument("-o", "--output", metavar="OUT.png",
                   help="where the PNG goes (default: FILE with .png for its suffix)")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Write the PNG; returns 0.  Raises InputError for bad input, a
    ReadFault when the disk fails the recording's read, OutputError when it
    refuses the PNG."""
    args = build_parser().parse_args(list(argv) if argv is not None else None)
    from stairbot.recording.plot import check_extra, render
    from stairbot.recording.read import read_recording

    check_extra()
    recording = read_recording(args.file)
    out = Path(args.output) if args.output else Path(args.file).with_suffix(".png")
    png = render(recording)
    f = LineFile(out, "the plot")
    try:
        f.write(png)
    finally:
        f.close()
    tel = recording.telemetry
    events = len(recording.events)
    what = (f"{len(tel.time_s)} ticks, {events} events" if tel.time_s
            else f"{events} events: a record of events alone" if recording.kind == "jsonl"
            else f"no tick, {events} events")
    cut = "" if recording.complete else "; the recording is cut short, read up to its end"
    print(f"wrote {shown(out)} ({what}{cut})")
    return 0
