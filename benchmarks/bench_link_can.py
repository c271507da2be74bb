"""Control-cycle rate and latency over python-can against the fake boards,
and the share of a 1 Mbit/s CAN bus the control loop uses.

A cycle is what the run loop does each tick over the wire: read every sensor
and motor (ReadAll to both boards: one broadcast frame) and send the
commands (SetWheelSpeeds + SetLiftSpeeds, their Acks checked on the next
cycle, or awaited in the same cycle).  The fake boards run in real time, as
`stairbot fake-boards --can` does: on ``virtual`` in a thread of this process,
on ``udp_multicast`` in another process on this host.  Beside the measured
figures it prints, for exactly the frames a cycle puts on the bus, the bits
they take at worst (bit stuffing, 29-bit ids: 160 bits for an 8-byte frame, see
``drivers.can_wire.frame_bits``), the rate a 1 Mbit/s bus would allow, and the
bus load at the controller's own tick (0.02 s), which must stay <= 20 %.

    python benchmarks/bench_link_can.py [--cycles N]
"""

from __future__ import annotations

import argparse
import random
import statistics
import subprocess
import sys
import threading
from collections.abc import Callable
from pathlib import Path

import can

from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.drivers.can_robot import open_can_robot
from stairbot.drivers.can_wire import frame_bits, wire
from stairbot.fakes.boards import make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.can_boards import CanBoardServer
from stairbot.inputs.scenario import load_scenario
from stairbot.run.robots import RobotOptions

# The cycle and its statistics are the serial benchmark's (this file's folder
# is on the path whether it runs alone or from bench_link.py).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_link import measure, percentile  # noqa: E402

BITRATE = 1_000_000
LOAD_LIMIT = 0.20
WARMUP = 100  # cycles before the measured ones


def cycle_frames(sensors: int = 4) -> list[tuple[str, int, int]]:
    """(frame name, data bytes, count) of every frame one control cycle puts on
    the bus, both ways, taken from the DBC; ``sensors``: the sensor board's
    channels (6: the side pair)."""
    w = wire()
    sent = [(15, m.ReadAll()), (1, m.SetWheelSpeeds(0, 0, 0, 0)),
            (1, m.SetLiftSpeeds(0, 0)),
            (1, m.Status(0, 0, 250, 0)), (2, m.Status(0, 0, 250, 0)),
            *((1, m.MotorTelemetry(c, 1, 0, 0, 0)) for c in range(6)),
            *((2, m.SensorTelemetry(c, 0, 0, 0, 0)) for c in range(sensors)),
            *((2, m.ImuTelemetry(a, 0, 0, 0, 0)) for a in m.IMU_AXES),
            (1, m.Ack(0x20, 0)), (1, m.Ack(0x21, 0))]
    counts: dict[str, list[int]] = {}
    for board, msg in sent:
        fid, data = w.encode(board, msg)
        name = w.db.get_message_by_frame_id(fid).name
        counts.setdefault(name, [len(data), 0])[1] += 1
    return [(name, size, n) for name, (size, n) in counts.items()]


def report(label: str, url: str, cycles: int) -> None:
    session = open_can_robot(url, load_config(), RobotOptions())
    robot = session.robot
    print(f"{label} ({url}), fake boards in real time, {cycles} cycles")
    for acked, name in ((False, "pipelined (Acks checked next cycle)"),
                        (True, "each Ack awaited in its cycle")):
        before = robot.health()  # type: ignore[attr-defined]
        rate, lat = measure(robot, cycles, acked, WARMUP)
        after = robot.health()  # type: ignore[attr-defined]
        bits = sum(after[k] - before[k] for k in ("bits_tx", "bits_rx")) / (cycles + WARMUP)
        print(f"  {name:38s} {rate:8.0f} cycles/s   latency median "
              f"{statistics.median(lat) * 1e3:.3f} ms  p99 {percentile(lat, 0.99) * 1e3:.3f} ms"
              f"  max {max(lat) * 1e3:.3f} ms   ({bits:.0f} bus bits a cycle, counted)")
    h = robot.health()  # type: ignore[attr-defined]
    print(f"  link: {h['frames_tx']:.0f} frames out, {h['frames_rx']:.0f} in, "
          f"{h['retries']:.0f} retries, {h['lost']:.0f} lost, {h['late']:.0f} late, "
          f"{h['malformed']:.0f} malformed, rtt median {h['rtt_median_ms']:.3f} ms "
          f"p99 {h['rtt_p99_ms']:.3f} ms")
    session.close()


def on_virtual(cycles: int) -> None:
    channel = f"bench-{random.randrange(1 << 30)}"
    world = make_world(load_config(), load_scenario(), False)
    server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world,
                            make_boards(world))
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    try:
        report("CAN on python-can virtual, boards on a thread", f"can://virtual/{channel}",
               cycles)
    finally:
        server.stop()
        thread.join(5)
        server.bus.shutdown()


def on_udp_multicast(cycles: int) -> None:
    group = f"239.74.{random.randrange(1, 255)}.{random.randrange(1, 255)}"
    spec = f"udp_multicast/{group}?port={random.randrange(40000, 60000)}"
    proc = subprocess.Popen([sys.executable, "-m", "stairbot", "fake-boards", "--can", spec],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        assert proc.stdout is not None
        url = proc.stdout.readline().strip()
        report("CAN on python-can udp_multicast, boards in another process", url, cycles)
    finally:
        proc.terminate()
        proc.wait(5)


def bus_budget(tick_s: float) -> None:
    frames = cycle_frames()
    bits = sum(frame_bits(size) * n for _, size, n in frames)
    count = sum(n for _, _, n in frames)
    load = bits / tick_s / BITRATE
    print(f"CAN bus budget at {BITRATE / 1e6:g} Mbit/s, worst-case stuffing "
          f"({frame_bits(8)} bits per 8-byte frame):")
    for name, size, n in frames:
        print(f"  {n} x {name:24s} {size} B  {frame_bits(size):3d} bits")
    print(f"  {count} frames, {bits} bits per cycle -> the bus allows "
          f"{BITRATE / bits:.0f} cycles/s")
    verdict = "ok" if load <= LOAD_LIMIT else "OVER THE LIMIT"
    print(f"  at the controller's tick of {tick_s} s: {bits / tick_s / 1e3:.1f} kbit/s = "
          f"{load:.1%} of the bus (limit {LOAD_LIMIT:.0%}: {verdict})")
    step = frame_bits(4) * 2  # lockstep only: StepTo + StepDone (simulation)
    print(f"  (lockstep simulation adds StepTo + StepDone: {step} bits, "
          f"{(bits + step) / tick_s / BITRATE:.1%})")
    side = cycle_frames(sensors=6)
    side_bits = sum(frame_bits(size) * n for _, size, n in side)
    print(f"  with the side pair (6 sensor channels): {sum(n for _, _, n in side)} frames, "
          f"{side_bits} bits, {side_bits / tick_s / BITRATE:.1%} "
          f"({(side_bits + step) / tick_s / BITRATE:.1%} in lockstep), the bus allows "
          f"{BITRATE / side_bits:.0f} cycles/s")


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    p.add_argument("--cycles", type=int, default=3000)
    args = p.parse_args(argv if argv is not None else [])
    runs: list[Callable[[int], None]] = [on_virtual, on_udp_multicast]
    for bench in runs:
        bench(args.cycles)
    bus_budget(load_config().algorithm.tick)


if __name__ == "__main__":
    main(sys.argv[1:])
