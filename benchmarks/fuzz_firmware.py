"""Fuzz the firmware's frame decoder under AddressSanitizer and
UndefinedBehaviorSanitizer; prints counts.

    python benchmarks/fuzz_firmware.py [--frames N] [--seed S] [--build-dir DIR]

Builds ``firmware/fuzz/fuzz_decoder.c`` with the portable core
(``firmware/core/*.c``) by the C compiler named by ``$CC``, else ``cc``,
``gcc`` or ``clang`` from PATH, with ``-fsanitize=address,undefined
-fno-sanitize-recover=all``, and feeds it ``--frames`` seeded random and
mutated frames (default 1,000,000; what each mutation is: the harness's
header comment).  A sanitizer report stops the harness: it counts as one
finding, and its report is printed.  The harness's own findings (a valid
frame refused, an accepted frame that re-encodes to other bytes) are counted
too.

Prints the command, the compiler, then the counts: frames, findings,
accepted and rejected frames (by error), and the stream reader's counts.
Exit status 0 with no finding, 1 with any, 2 without a C compiler or for bad
arguments, 3 when the compiler has no sanitizer runtime.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

from stairbot.fakes.firmware_boards import find_cc

FIRMWARE = Path(__file__).resolve().parent.parent / "firmware"
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all",
            "-fno-omit-frame-pointer", "-g"]
CFLAGS = ["-std=c11", "-O2", "-Wall", "-Wextra", "-Wpedantic", "-Werror"]
NO_SANITIZER = 3


def sanitizer_problem(cc: str, build_dir: Path) -> str | None:
    """Why ``cc`` cannot build and run a sanitized program here (None: it can)."""
    src, exe = build_dir / "probe.c", build_dir / "probe"
    src.write_text("int main(void) { return 0; }\n")
    made = subprocess.run([cc, *SANITIZE, str(src), "-o", str(exe)],
                          capture_output=True, text=True, check=False)
    if made.returncode != 0:
        return f"{cc} cannot link with {' '.join(SANITIZE[:2])}: {made.stderr.strip()[:300]}"
    ran = subprocess.run([str(exe)], capture_output=True, text=True, check=False)
    if ran.returncode != 0:
        return f"a sanitized program does not run here: {ran.stderr.strip()[:300]}"
    return None


def build(cc: str, build_dir: Path) -> Path:
    """The sanitized harness, built into ``build_dir``.  Raises CalledProcessError."""
    exe = build_dir / "fuzz_decoder"
    sources = sorted(str(p) for p in (FIRMWARE / "core").glob("*.c"))
    subprocess.run([cc, *CFLAGS, *SANITIZE, f"-I{FIRMWARE / 'core'}", *sources,
                    str(FIRMWARE / "fuzz" / "fuzz_decoder.c"), "-o", str(exe)],
                   check=True, capture_output=True, text=True)
    return exe


def positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number above 0")
    return value


def run(frames: int, seed: int, build_dir: Path) -> int:
    cc = find_cc()
    if cc is None:
        print("fuzz_firmware: no C compiler: set CC, or install gcc (scripts/test does)",
              file=sys.stderr)
        return 2
    problem = sanitizer_problem(cc, build_dir)
    if problem is not None:
        print(f"fuzz_firmware: {problem}", file=sys.stderr)
        return NO_SANITIZER
    try:
        exe = build(cc, build_dir)
    except subprocess.CalledProcessError as exc:
        print(f"fuzz_firmware: the harness does not build:\n{exc.stderr}", file=sys.stderr)
        return 2
    done = subprocess.run([str(exe), str(frames), str(seed)], capture_output=True, text=True,
                          check=False)
    counts = dict(line.split(" ", 1) for line in done.stdout.splitlines() if " " in line)
    sanitizer = ("Sanitizer" in done.stderr or "runtime error:" in done.stderr)
    findings = int(counts.get("findings", "0")) + (1 if sanitizer else 0)
    if done.returncode != 0 and not sanitizer and "findings" not in counts:
        findings += 1  # died without a report: a crash all the same
    print(f"command: {' '.join(sys.argv)}")
    print(f"compiler: {cc} {' '.join(SANITIZE[:2])}")
    print(f"frames: {counts.get('frames', '?')} (seed {seed})")
    print(f"findings: {findings}")
    print(f"accepted: {counts.get('accepted', '?')}")
    print(f"rejected: {counts.get('rejected', '?')}")
    for key, value in counts.items():
        if key not in ("frames", "findings", "accepted", "rejected"):
            print(f"  {key}: {value}")
    if done.stderr.strip():
        print(done.stderr.strip()[-4000:])
    return 1 if findings else 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", type=positive, default=1_000_000)
    parser.add_argument("--seed", type=positive, default=1)
    parser.add_argument("--build-dir", type=Path, default=None,
                        help="where to build (default: a temporary directory)")
    args = parser.parse_args(argv)
    if args.build_dir is not None:
        args.build_dir.mkdir(parents=True, exist_ok=True)
        return run(args.frames, args.seed, args.build_dir)
    with tempfile.TemporaryDirectory(prefix="fuzz_firmware") as tmp:
        return run(args.frames, args.seed, Path(tmp))


if __name__ == "__main__":
    sys.exit(main())
