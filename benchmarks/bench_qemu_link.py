"""Host control cycles per second against the motor board of the
qemu-stm32f4 port, over QEMU's emulated USART1 on a pseudo-terminal; and
the image's flash and RAM.

A cycle is the host's over the serial line to the motor board: one ReadAll
frame and one SetWheelSpeeds frame written together (both in flight, as the
run loop sends them), then both replies awaited (the Status and six
MotorTelemetry, the Ack).  The host holds the lease (Claim, SetWatchdog 250
ms, fed by the cycles).  Each figure is the median of 3 runs of --cycles
cycles on one QEMU; the same cycle against the native board on a pty
(firmware/native, sb_motor_native) is printed beside it for comparison.

Then lockstep ticks per second on the plant-link image
(sb_motor_qemu_link.elf, its USART2 answered from the simulated robot by
stairbot.fakes.plant_link): a tick is SetWheelSpeeds + StepTo (20 ms on)
in one frame and a ReadAll in another, both in flight; the motor board
alone, so what a lockstep run on QEMU's firmware would get at best.

    python benchmarks/bench_qemu_link.py [--cycles N]

Needs make, arm-none-eabi-gcc with picolibc and qemu-system-arm (exit
status 2 without them, saying which is missing); the native figure needs a
C compiler too (left out without one).
"""

from __future__ import annotations

import argparse
import os
import secrets
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import tty
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from qemu_board import FIRMWARE, build_images, missing_tools, run_board, run_linked  # noqa: E402

from stairbot.control.robot_config import load_config  # noqa: E402
from stairbot.drivers import messages as m  # noqa: E402
from stairbot.drivers.handshake import open_board, release_board  # noqa: E402
from stairbot.drivers.serial_link import FdChannel, SerialLink  # noqa: E402
from stairbot.drivers.serial_wire import Frame, encode_frame  # noqa: E402
from stairbot.fakes import sim_messages as sm  # noqa: E402
from stairbot.inputs.scenario import load_scenario  # noqa: E402

MOTOR = m.Board.MOTOR
NONCE = 0xBE7C
RUNS = 3
WARMUP = 50
TICK_US = 20_000


def cycles_per_s(path: str, cycles: int) -> tuple[list[float], list[float]]:
    """RUNS measurements of ``cycles`` cycles each on the board at ``path``
    (cycles/s), and every cycle's time (s)."""
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    tty.setraw(fd)
    link = SerialLink(FdChannel(fd), timeout_s=0.2)
    try:
        open_board(link, f"serial://{path}", MOTOR, lockstep=False, watchdog_ms=250,
                   hold_ms=0, nonce=NONCE, lease_ms=1000, wait_s=time.sleep,
                   allow_latched=True)

        def cycle() -> None:
            read = link.request(MOTOR, [m.ReadAll()], send=False)
            command = link.request(MOTOR, [m.SetWheelSpeeds(300, 300, 300, 300)], send=False)
            status, ack = link.wait([read, command])
            assert len(status.messages) == 7, status.messages
            assert ack.messages == (m.Ack(m.SetWheelSpeeds.TYPE, m.AckResult.OK),), ack.messages

        for _ in range(WARMUP):
            cycle()
        rates, times = [], []
        for _ in range(RUNS):
            t0 = time.perf_counter()
            for _ in range(cycles):
                c0 = time.perf_counter()
                cycle()
                times.append(time.perf_counter() - c0)
            rates.append(cycles / (time.perf_counter() - t0))
        link.exchange(MOTOR, [m.Stop(m.ALL_MOTORS_MASK), m.SetWatchdog(0, 0)])
        return rates, times
    finally:
        release_board(link, MOTOR, NONCE)
        link.close()


def report(name: str, measured: tuple[list[float], list[float]]) -> None:
    rates, times = measured
    shown = ", ".join(f"{r:.0f}" for r in rates)
    ordered = sorted(times)
    p99 = ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))]
    print(f"  {name}: {statistics.median(rates):.0f} cycles/s (median of {shown}); "
          f"a cycle {statistics.median(times) * 1e3:.2f} ms median, {p99 * 1e3:.2f} ms p99")


def cycle_bytes() -> tuple[int, int]:
    """(host -> board, board -> host) bytes on the wire per cycle."""
    s = 0x5A  # a host session
    out = [Frame(MOTOR, 1, (m.ReadAll(),), session=s),
           Frame(MOTOR, 2, (m.SetWheelSpeeds(300, 300, 300, 300),), session=s)]
    back = [Frame(MOTOR, 1, (m.Status(0, 0, 250, 0), *(
                m.MotorTelemetry(c, 1, 0, 300, 123456) for c in range(6))), True, s),
            Frame(MOTOR, 2, (m.Ack(m.SetWheelSpeeds.TYPE, 0),), True, s)]
    return sum(len(encode_frame(f)) for f in out), sum(len(encode_frame(f)) for f in back)


def native_rates(build: Path, cycles: int) -> tuple[list[float], list[float]] | None:
    """The same cycles against sb_motor_native on its own pty (None without
    a C compiler)."""
    if not any(shutil.which(cc) for cc in ("cc", "gcc", "clang")):
        return None
    exe = build / "sb_motor_native"
    subprocess.run(["make", "-s", "-C", str(FIRMWARE), f"BUILD={build}", str(exe)], check=True)
    proc = subprocess.Popen([str(exe)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                            stdin=subprocess.DEVNULL, text=True)
    try:
        assert proc.stdout is not None
        return cycles_per_s(proc.stdout.readline().strip(), cycles)
    finally:
        proc.terminate()
        proc.wait(10)


def lockstep_ticks_per_s(program: Path, ticks: int) -> list[float]:
    """RUNS measurements of ``ticks`` lockstep ticks each on the plant-link image."""
    with run_linked(program, MOTOR, load_config(), load_scenario(), serial=1) as (board, link):
        open_board(link, "qemu", MOTOR, lockstep=True, watchdog_ms=250, hold_ms=0,
                   nonce=NONCE, lease_ms=5000, wait_s=time.sleep)
        now_us = round(board.plant.world.now() * 1e6)
        rates = []
        for _ in range(RUNS):
            t0 = time.perf_counter()
            for _ in range(ticks):
                now_us += TICK_US
                step = link.request(MOTOR, [m.SetWheelSpeeds(300, 300, 300, 300),
                                            sm.StepTo(now_us)], send=False)
                read = link.request(MOTOR, [m.ReadAll()], send=False)
                stepped, _ = link.wait([step, read])
                assert stepped.messages[1] == sm.StepDone(now_us), stepped.messages
            rates.append(ticks / (time.perf_counter() - t0))
        release_board(link, MOTOR, NONCE)
        return rates


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cycles", type=int, default=1000, help="cycles a run (default 1000)")
    args = p.parse_args()
    missing = missing_tools()
    if missing:
        print(f"bench_qemu_link: missing {', '.join(missing)} (Debian: make "
              "gcc-arm-none-eabi picolibc-arm-none-eabi qemu-system-arm)", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory() as tmp:
        images = build_images(Path(tmp))
        elf = images / "sb_motor_qemu.elf"
        size = subprocess.run(["arm-none-eabi-size", str(elf)], capture_output=True, text=True,
                              check=True).stdout.splitlines()[1].split()
        text, data, bss = (int(x) for x in size[:3])
        print(f"{elf.name} (arm-none-eabi-gcc -Os, Cortex-M4): flash {text + data} bytes "
              f"(text {text} + data {data}), RAM {data + bss} bytes (data {data} + bss {bss}; "
              "the stack's 4 KB reserve apart)")
        tx, rx = cycle_bytes()
        print(f"host control cycles (ReadAll + SetWheelSpeeds in flight together: {tx} bytes "
              f"to the board, {rx} back), {args.cycles} a run:")
        with run_board(elf, secrets.randbits(32) | 1) as board:
            report(f"qemu netduinoplus2, USART1 on {board.path}", cycles_per_s(board.path,
                                                                                 args.cycles))
        native = native_rates(Path(tmp), args.cycles)
        if native is not None:
            report("native sb_motor_native on a pty", native)
        ticks = max(1, args.cycles // 5)
        rates = lockstep_ticks_per_s(images / "sb_motor_qemu_link", ticks)
        shown = ", ".join(f"{r:.0f}" for r in rates)
        median = statistics.median(rates)
        print(f"lockstep on the plant-link image (SetWheelSpeeds + StepTo 20 ms, ReadAll), "
              f"{ticks} ticks a run: {median:.0f} ticks/s (median of {shown}) = "
              f"{median * TICK_US / 1e6:.1f} x real time")
    return 0


if __name__ == "__main__":
    sys.exit(main())
