"""Control-cycle rate and latency of the serial link against the fake boards.

A cycle is what the run loop does each tick over the wire: read every sensor
and motor (one ReadAll to each board, both in flight at once) and send the
commands (one SetWheelSpeeds + SetLiftSpeeds frame).  The fake boards run in
another process on a pseudo-terminal, in real time, as `stairbot fake-boards
--serial` does.  Beside the measured figures it prints the rate the wire
itself would allow at 1 Mbaud (UART 8N1: 10 bits a byte) for exactly the
frames a cycle sends.

    python benchmarks/bench_link.py [--cycles N]

The CAN part lives in bench_link_can.py (run by this script when present).
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import stairbot.fakes.lockstep  # noqa: F401 - registers the lockstep robot with the drivers
from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.drivers import units as u
from stairbot.drivers.serial_robot import open_serial_robot
from stairbot.drivers.serial_wire import Frame, encode_frame
from stairbot.hardware import MotorId
from stairbot.run.robots import RobotOptions

BAUD = 1_000_000
BITS_PER_BYTE = 10  # 8N1


def cycle_bytes(sensors: int = 4) -> tuple[int, int]:
    """(host -> boards, boards -> host) bytes on the wire per cycle, for a
    sensor board of ``sensors`` channels (6: the side pair)."""
    status = m.Status(0, 0, 250, 0)
    s = 0x5A  # a host session (a zero would cost COBS a byte)
    tx = [Frame(1, 1, (m.ReadAll(),), session=s), Frame(2, 2, (m.ReadAll(),), session=s),
          Frame(1, 3, u.speeds_to_wire({}), session=s)]
    rx = [Frame(1, 1, (status, *(m.MotorTelemetry(c, 1, 0, 1000, 123456) for c in range(6))),
                True, s),
          Frame(2, 2, (status, *(m.SensorTelemetry(c, 0, 500, 7, 12) for c in range(sensors)),
                       *(m.ImuTelemetry(a, 0, -250, 15, 3) for a in m.IMU_AXES)), True, s),
          Frame(1, 3, (m.Ack(0x20, 0), m.Ack(0x21, 0)), True, s)]
    return sum(len(encode_frame(f)) for f in tx), sum(len(encode_frame(f)) for f in rx)


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def measure(robot: object, cycles: int, acked: bool, warmup: int = 200
            ) -> tuple[float, list[float]]:
    """Cycles per second and each cycle's latency (s) over ``cycles`` cycles,
    after ``warmup`` cycles; with ``acked`` each cycle also waits for its Acks.
    Shared with bench_link_can.py."""
    speeds = {mid: 0.0 for mid in MotorId}
    lat: list[float] = []
    read, command = robot.read, robot.command  # type: ignore[attr-defined]
    flush = robot.flush  # type: ignore[attr-defined]
    for _ in range(warmup):
        read()
        command(speeds)
    flush()
    t0 = time.perf_counter()
    for _ in range(cycles):
        c0 = time.perf_counter()
        read()
        command(speeds)
        if acked:
            flush()
        lat.append(time.perf_counter() - c0)
    total = time.perf_counter() - t0
    return cycles / total, lat


def bench_serial(cycles: int) -> None:
    proc = subprocess.Popen([sys.executable, "-m", "stairbot", "fake-boards", "--serial"],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                            cwd=tempfile.gettempdir())
    try:
        assert proc.stdout is not None
        url = proc.stdout.readline().strip()
        session = open_serial_robot(url, load_config(), RobotOptions())
        robot = session.robot
        tx, rx = cycle_bytes()
        print(f"serial over a pseudo-terminal ({url}), fake boards in real time, "
              f"{cycles} cycles")
        for acked, name in ((False, "pipelined (Ack checked next cycle)"),
                            (True, "each Ack awaited in its cycle")):
            rate, lat = measure(robot, cycles, acked)
            print(f"  {name:38s} {rate:8.0f} cycles/s   latency median "
                  f"{statistics.median(lat) * 1e3:.3f} ms  p99 {percentile(lat, 0.99) * 1e3:.3f}"
                  f" ms  max {max(lat) * 1e3:.3f} ms")
        h = robot.health()  # type: ignore[attr-defined]
        print(f"  link: {h['frames_tx']:.0f} frames out, {h['frames_rx']:.0f} in, "
              f"{h['retries']:.0f} retries, {h['crc_errors']:.0f} CRC errors, "
              f"{h['lost']:.0f} lost, rtt median {h['rtt_median_ms']:.3f} ms "
              f"p99 {h['rtt_p99_ms']:.3f} ms")
        bits = BITS_PER_BYTE / BAUD
        print(f"  wire at 1 Mbaud 8N1: {tx} B out + {rx} B in per cycle -> "
              f"{1 / (max(tx, rx) * bits):.0f} cycles/s full duplex, "
              f"{1 / ((tx + rx) * bits):.0f} cycles/s half duplex (RS-485)")
        tx, rx = cycle_bytes(sensors=6)
        print(f"  the same with the side pair (6 sensor channels): {tx} B out + {rx} B in "
              f"-> {1 / (max(tx, rx) * bits):.0f} cycles/s full duplex, "
              f"{1 / ((tx + rx) * bits):.0f} half duplex")
        session.close()
    finally:
        proc.terminate()
        proc.wait(5)


def bench_lockstep(ticks: int) -> None:
    """Ticks per second of a lockstep run's loop over the pty (speeds, StepTo
    and both ReadAlls in one write, physics included): what bounds a full
    simulated run over the wire."""
    proc = subprocess.Popen([sys.executable, "-m", "stairbot", "fake-boards", "--serial",
                             "--lockstep"], stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True,
                            cwd=tempfile.gettempdir())
    try:
        assert proc.stdout is not None
        url = proc.stdout.readline().strip()
        config = load_config()
        session = open_serial_robot(url, config, RobotOptions())
        robot, clock, tick = session.robot, session.clock, config.algorithm.tick
        speeds = {MotorId.MWF: 0.5, MotorId.MWB: 0.5, MotorId.MWR: 0.5, MotorId.MWL: 0.5}
        t0 = time.perf_counter()
        for _ in range(ticks):
            robot.read()
            robot.command(speeds)
            clock.advance(tick)
        rate = ticks / (time.perf_counter() - t0)
        print(f"lockstep over the pty ({url}): {rate:.0f} ticks/s = "
              f"{rate * tick:.1f} x real time with the {tick * 1e3:.0f} ms tick")
        session.close()
    finally:
        proc.terminate()
        proc.wait(5)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cycles", type=int, default=5000)
    args = p.parse_args()
    bench_serial(args.cycles)
    bench_lockstep(args.cycles // 2)
    can = Path(__file__).with_name("bench_link_can.py")
    if can.exists():
        spec = importlib.util.spec_from_file_location("bench_link_can", can)
        if spec and spec.loader:
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            module.main()


if __name__ == "__main__":
    main()
