"""The C motor board (firmware/board, on the native plant and a scripted
clock: firmware/test/sbboard.c) against the Python fake motor board
(stairbot/fakes/boards.py behind serial_boards.SerialBoardServer, its
duplicate cache) step by step, frame by frame, on the same plant: every
reply alike, and the plants alike after every frame."""

from __future__ import annotations

import dataclasses
import random
import select
import socket
import subprocess
from collections.abc import Callable, Mapping
from fractions import Fraction
from pathlib import Path

from board_host import reached_by_any_board
from cobs import cobs
from firmware_build import LIFT_LIMIT, SANITIZE, WHEEL_LIMIT, build

from stairbot.drivers import messages as m
from stairbot.drivers.serial_wire import Frame, FrameReader, RawMessage, encode_frame, parse_body
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import MotorBoard
from stairbot.fakes.serial_boards import SerialBoardServer
from stairbot.hardware import MotorId, MotorState, Snapshot, Truth

MOTOR = m.Board.MOTOR


class PlantRobot:
    """firmware/native/plant.c in Python, on the Python fake board's side:
    each counter integrates its commanded speed (clamped to the plant's
    limits) in micro-turns; a lift stops at the end of its stroke and says
    "limit".  Time is whole milliseconds; the counters go to the fake as
    floats of turns, as the simulation's do."""

    LIFTS = (m.MOTOR_CHANNELS[4], m.MOTOR_CHANNELS[5])
    STROKE_UMT = 105_000_000

    def __init__(self, lift_mt: int) -> None:
        self.now_ms = 0
        self.cmd = {mid: 0 for mid in m.MOTOR_CHANNELS}
        self.umt = {mid: 0 for mid in m.MOTOR_CHANNELS}
        self.umt[self.LIFTS[0]], self.umt[self.LIFTS[1]] = lift_mt * 1000, -lift_mt * 1000
        self.measured = {mid: 0 for mid in m.MOTOR_CHANNELS}
        self.at_limit = {mid: False for mid in m.MOTOR_CHANNELS}
        self.injected: dict[MotorId, str | None] = {mid: None for mid in m.MOTOR_CHANNELS}

    def clamped(self, mid: MotorId) -> int:
        """The motor's commanded speed within its limit (mturn/s)."""
        limit = LIFT_LIMIT if mid in self.LIFTS else WHEEL_LIMIT
        return max(-limit, min(limit, self.cmd[mid]))

    def advance_to(self, t_ms: int) -> None:
        dt, self.now_ms = t_ms - self.now_ms, t_ms
        if dt == 0:
            return
        for mid in m.MOTOR_CHANNELS:
            v = self.clamped(mid)
            pos = self.umt[mid] + v * dt
            self.at_limit[mid] = mid in self.LIFTS and abs(pos) > self.STROKE_UMT
            if self.at_limit[mid]:
                pos, v = max(-self.STROKE_UMT, min(self.STROKE_UMT, pos)), 0
            self.umt[mid], self.measured[mid] = pos, v

    def read(self) -> Snapshot:
        def mt(umt: int) -> int:  # plant.c's rounding: a half away from zero
            return (umt + 500) // 1000 if umt >= 0 else -((-umt + 500) // 1000)
        return Snapshot(Fraction(self.now_ms, 1000), {}, {  # type: ignore[arg-type]
            mid: MotorState(mt(self.umt[mid]) / 1000, self.measured[mid] / 1000,
                            self.injected[mid] or ("lift limit" if self.at_limit[mid] else None))
            for mid in m.MOTOR_CHANNELS})

    def command(self, speeds: Mapping[MotorId, float]) -> None:
        for mid, tps in speeds.items():
            self.cmd[mid] = round(tps * 1000)

    def stop_all(self) -> None:
        self.cmd = {mid: 0 for mid in m.MOTOR_CHANNELS}

    def truth(self) -> Truth:
        return Truth(False, None, 0.0, 0.0, 0.0)


class PlantClock:
    """The scripted clock: exact (a Fraction of seconds), so the fake's
    watchdog, hold and lease compare whole milliseconds as the C board does."""

    def __init__(self, robot: PlantRobot) -> None:
        self.robot = robot

    def now(self) -> Fraction:
        return Fraction(self.robot.now_ms, 1000)


def random_request(rng: random.Random) -> m.Message | RawMessage:
    """One request of the kinds a host sends, with values near the edges
    that matter (channels and masks past the last, speeds past the limits,
    Moves of speed 0, watchdogs and holds short enough to trip)."""
    kinds: list[Callable[[], m.Message | RawMessage]] = [
        lambda: m.Identify(), lambda: m.GetStatus(), lambda: m.Heartbeat(rng.randrange(256)),
        lambda: m.ReadAll(), lambda: m.ReadAll(), lambda: m.ReadAll(),
        lambda: m.GetMotor(rng.randrange(8)), lambda: m.Clear(rng.choice([1, 2, 4, 7, 7])),
        lambda: m.Claim(rng.choice([0, 200, 1000, 1000]), rng.choice([1, 1, 2])),
        lambda: m.SetWatchdog(rng.choice([0, 0, 100, 250]), rng.choice([0, 0, 60])),
        lambda: m.SetWheelSpeeds(*(rng.randint(-1500, 1500) for _ in range(4))),
        lambda: m.SetLiftSpeeds(rng.randint(-2000, 12000), rng.randint(-12000, 2000)),
        lambda: m.SetLiftSpeeds(rng.randint(-2000, 12000), rng.randint(-12000, 2000)),
        lambda: m.Run(rng.randrange(7), rng.randint(-1500, 1500)),
        lambda: m.Move(rng.randrange(7), rng.randint(-400, 400), rng.choice([0, 300, 997, 5000])),
        lambda: m.Move(rng.randrange(6), rng.randint(-400, 400), rng.choice([300, 997, 5000])),
        lambda: m.Stop(rng.choice([0x01, 0x0F, 0x30, 0x3F, 0x40])),
        lambda: m.Brake(rng.choice([0x01, 0x0F, 0x30, 0x3F, 0x80])),
        lambda: m.EStop() if rng.random() < 0.3 else m.GetStatus(),
        lambda: m.GetSensor(0), lambda: RawMessage(0x55, b"\x01"),
    ]
    return rng.choice(kinds)()


FRAMES = 4000
FAULT_NAMES = {3: "overcurrent", 4: "stall", 5: "encoder", 7: "driver fault"}
"""The motor faults a script injects (MotorFault code: the plant's words)."""


def test_the_c_board_answers_as_the_python_fake_board_step_by_step(
        tmp_path: Path) -> None:
    """The C board built with AddressSanitizer and UBSan (no report), and
    4,000 frames of two hosts (sessions 7 and 9, each with its own
    sequence numbers, a frame now and then sent again as a retry is), with
    the clock moving 0 to 400 ms between them: every reply frame the same,
    field by field, but Owner.lease_cs (the fake rounds a float: within 1);
    and the script reaches what it is meant to (retries answered from the
    cache, every Ack result, every Claim result, both latches, Moves that
    reach their stop points, a lift at its limit, a reply frame cut at 247
    message bytes); after every frame the two plants stand in the same
    place with their motors commanded alike."""
    exe = build(tmp_path / "sbboard", ("core", "board"),
                ("native/plant.c", "test/sbline.c", "test/sbboard.c"), ["-O1", "-g", *SANITIZE])
    boot, lift_mt = 0xB007, 103_000  # the lifts start 2 turns from the ends of their stroke
    robot = PlantRobot(lift_mt)
    world = BoardWorld(robot, PlantClock(robot))  # type: ignore[arg-type]
    fake = MotorBoard(world, serial=1)
    fake.boot = fake.lease.boot = boot
    ours, theirs = socket.socketpair()
    server = SerialBoardServer(ours.fileno(), world, {int(MOTOR): fake})
    theirs.setblocking(False)
    rng = random.Random(37)
    t_ms, seqs, last = 0, {7: 0, 9: 0}, {7: b"", 9: b""}
    commands, frames = [], []
    for _ in range(FRAMES):
        t_ms += rng.choice([0, 1, 3, 10, 30, 60, 100, 120, 250, 400])  # 100, 250: on a watchdog
        if commands and commands[-2].startswith("f "):
            t_ms += 1  # past the instant a fault was read at (the fake's world is read once)
        session = rng.choice([7, 7, 7, 9])
        if last[session] and rng.random() < 0.1:
            wire = last[session]  # a retry: the same bytes
        else:
            seqs[session] = (seqs[session] + 1) & 0xFF
            msgs = tuple(random_request(rng) for _ in range(rng.choice([1, 1, 2, 3])))
            wire = encode_frame(Frame(MOTOR, seqs[session], msgs, session=session))
        last[session] = wire
        fault = None
        if rng.random() < 0.02:
            # a motor's own fault from the next instant (the fake reads its world once an
            # instant), read by a ReadAll then, and gone after it: both boards latch it
            # there (the C board as it polls, the fake as it reads)
            t_ms += 1
            fault = (rng.randrange(6), rng.choice(list(FAULT_NAMES)))
            seqs[7] = (seqs[7] + 1) & 0xFF
            wire = encode_frame(Frame(MOTOR, seqs[7], (m.ReadAll(),), session=7))
            last[7] = wire
            commands += [f"f {fault[0]} {fault[1]}", f"t {t_ms}", f"w {wire.hex()}",
                         f"f {fault[0]} 0", "s"]
        else:
            commands += [f"t {t_ms}", f"w {wire.hex()}", "s"]
        frames.append((t_ms, wire, fault))
    for seq in (200, 201):  # more replies than a frame holds: the rest left off, alike
        wire = encode_frame(Frame(MOTOR, seq, (m.ReadAll(),) * 4 + (m.Identify(),), session=7))
        commands += [f"t {t_ms}", f"w {wire.hex()}", "s"]
        frames.append((t_ms, wire, None))
    with subprocess.Popen([str(exe), str(boot), str(lift_mt)], stdin=subprocess.PIPE,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as proc:
        out, err = proc.communicate("".join(c + "\n" for c in commands), timeout=60)
    assert proc.returncode == 0 and not err, err  # no sanitizer report
    lines = [line for line in out.splitlines() if line != "ok"]  # t's and f's
    answers, plants = lines[0::2], lines[1::2]
    assert len(answers) == len(plants) == len(frames)
    seen: set[str] = set()
    try:
        for i, ((t, wire, fault), c_hex, c_plant) in enumerate(zip(frames, answers, plants,
                                                                    strict=True)):
            if fault is not None:
                robot.injected[m.MOTOR_CHANNELS[fault[0]]] = FAULT_NAMES[fault[1]]
            robot.advance_to(t)
            fake.poll()
            server.receive(wire)
            if fault is not None:
                robot.injected[m.MOTOR_CHANNELS[fault[0]]] = None
            py = theirs.recv(4096) if select.select([theirs], [], [], 0)[0] else b""
            # the plant in the same place, its motors commanded alike (the C board clamps
            # a speed to the motor's limit; behind the Python fake the plant does)
            py_plant = [robot.umt[mid] for mid in m.MOTOR_CHANNELS] + [
                robot.clamped(mid) for mid in m.MOTOR_CHANNELS]
            assert [int(x) for x in c_plant.split()] == py_plant, (
                i, t, parse_body(cobs_body(wire)))
            c = b"" if c_hex == "-" else bytes.fromhex(c_hex)
            py_frames, c_frames = FrameReader().feed(py), FrameReader().feed(c)
            c_same, py_same = [same_lease(f) for f in c_frames], [same_lease(f) for f in py_frames]
            assert c_same == py_same, (i, t, parse_body(cobs_body(wire)), first_difference(
                c_same, py_same))
            for cf, pf in zip(c_frames, py_frames, strict=True):
                for cm, pm in zip(cf.messages, pf.messages, strict=True):
                    if isinstance(cm, m.Owner) and isinstance(pm, m.Owner):
                        assert abs(cm.lease_cs - pm.lease_cs) <= 1, (i, cm, pm)
                    seen.update(reached(cm))
                if len(cf.messages) < sum(7 if isinstance(x, m.ReadAll) else 1
                                          for x in parse_body(cobs_body(wire)).messages):
                    seen.add("cut")
    finally:
        ours.close()
        theirs.close()
    assert server.stats.duplicates > 50
    wanted = {f"ack {r.name}" for r in m.AckResult if r != m.AckResult.BAD_LENGTH}
    wanted |= {f"claim {r.name}" for r in m.ClaimResult}
    wanted |= {"estop", "watchdog", "mode MOVE", "mode BRAKE", "mode HOLD", "fault LIMIT", "cut",
               "status FAULT", *(f"fault {m.MotorFault(c).name}" for c in FAULT_NAMES)}
    assert wanted <= seen, wanted - seen


def reached(msg: m.Message | RawMessage) -> set[str]:
    """What a reply shows the script reached."""
    if isinstance(msg, m.MotorTelemetry):
        return {f"mode {m.MotorMode(msg.mode).name}"} | (
            {f"fault {m.MotorFault(msg.fault).name}"} if msg.fault not in (
                m.MotorFault.NONE, m.MotorFault.ESTOP, m.MotorFault.WATCHDOG) else set())
    return reached_by_any_board(msg)


def first_difference(c: list[Frame], py: list[Frame]) -> str:
    """Where two lists of reply frames first differ, in words."""
    if len(c) != len(py):
        return f"C sent {len(c)} frame(s), Python {len(py)}"
    for cf, pf in zip(c, py, strict=True):
        for j, (cm, pm) in enumerate(zip(cf.messages, pf.messages, strict=False)):
            if cm != pm:
                return f"reply {j}: C {cm}, Python {pm}"
        if cf != pf:
            return f"C {cf}, Python {pf}"
    return "none"


def same_lease(frame: Frame) -> Frame:
    """``frame`` with Owner.lease_cs left out (compared apart, within 1)."""
    return dataclasses.replace(frame, messages=tuple(
        dataclasses.replace(x, lease_cs=0) if isinstance(x, m.Owner) else x
        for x in frame.messages))


def cobs_body(wire: bytes) -> bytes:
    return cobs.decode(wire[:-1])
