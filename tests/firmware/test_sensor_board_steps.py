"""The C sensor board (firmware/board/sb_sensor.c, on a scripted clock and
sensor plant: firmware/test/sbsensor.c) against the Python fake sensor
board (stairbot/fakes/boards.py behind serial_boards.SerialBoardServer, its
duplicate cache) step by step, frame by frame, on the same scripted
readings: every reply alike.  Mutants of the C board (an age truncated, a
sample counted on every read, ...) fail the same comparison."""

from __future__ import annotations

import dataclasses
import math
import random
import select
import socket
import subprocess
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path

import pytest
from board_host import reached_by_any_board
from firmware_build import FIRMWARE, SANITIZE, build

from stairbot.drivers import messages as m
from stairbot.drivers.serial_wire import Frame, FrameReader, RawMessage, encode_frame
from stairbot.fakes import sim_messages as sim
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import SensorBoard
from stairbot.fakes.serial_boards import SerialBoardServer
from stairbot.hardware import Imu, SensorReading, SensorStatus, Snapshot, Truth

SENSOR = m.Board.SENSOR
STATUS = {0: SensorStatus.OK, 1: SensorStatus.OUT_OF_RANGE, 2: SensorStatus.ERROR}
Range = tuple[int, int, int]  # SensorCode, mm, measured_us
Axis = tuple[int, int, int, int]  # ImuCode, cdeg, ddps, measured_us


@dataclasses.dataclass
class Readings:
    """The scripted plant at one instant: each channel's latest measurement
    (None: never measured) and the IMU's two axes (None: no IMU)."""

    now_ms: int
    ranges: list[Range | None]
    imu: list[Axis] | None

    def age_us(self, msg: m.SensorTelemetry | m.ImuTelemetry) -> int | None:
        """The exact age of the reading a telemetry message reports (None: none)."""
        if isinstance(msg, m.SensorTelemetry):
            r = self.ranges[msg.channel] if msg.channel < len(self.ranges) else None
            return None if r is None else self.now_ms * 1000 - r[2]
        return None if self.imu is None else self.now_ms * 1000 - self.imu[msg.axis][3]


def seconds(us: int) -> float:
    """Microseconds as an exact Fraction of seconds (where the fake takes a float)."""
    return Fraction(us, 10**6)  # type: ignore[return-value]


class ScriptedSensors:
    """The Python fake's Robot: the script's readings as a Snapshot at the
    clock's time, each reading's age counted back from it exactly (a
    Fraction of seconds), so the fake's measurement times are the script's
    microseconds.  ERROR on an IMU axis goes as an angle that is not a
    number, which the fake sends as ERROR."""

    def __init__(self, channels: int) -> None:
        self.now = Readings(0, [None] * channels, None)

    def read(self) -> Snapshot:
        now_us = self.now.now_ms * 1000
        sensors = {m.SENSOR_CHANNELS[ch]: SensorReading(mm / 1000, STATUS[code],
                                                        seconds(now_us - us))
                   for ch, r in enumerate(self.now.ranges) if r is not None
                   for code, mm, us in (r,)}
        imu = None
        if self.now.imu is not None:
            (pc, pa, pr, pus), (rc, ra, rr, rus) = self.now.imu
            assert pus == rus  # the fake's Imu has one age for both axes
            imu = Imu(math.nan if pc else pa / 100, math.nan if rc else ra / 100, pr / 10,
                      rr / 10, seconds(now_us - pus))
        return Snapshot(Fraction(self.now.now_ms, 1000), sensors, {}, imu=imu)  # type: ignore[arg-type]

    def command(self, speeds: object) -> None:
        raise AssertionError("the sensor board drives no motor")

    def stop_all(self) -> None:
        pass

    def truth(self) -> Truth:
        return Truth(False, None, 0.0, 0.0, 0.0)


class ScriptedClock:
    """The scripted clock in whole milliseconds, exact (a Fraction of
    seconds), so the fake's watchdog and lease compare as the C board does."""

    def __init__(self, robot: ScriptedSensors) -> None:
        self.robot = robot

    def now(self) -> Fraction:
        return Fraction(self.robot.now.now_ms, 1000)


def random_request(rng: random.Random, channels: int) -> m.Message | RawMessage:
    """One request of the kinds a host sends a sensor board, and what it
    must refuse: channels and axes past the last, motor commands, the
    simulation's messages, a board's message, an unknown type."""
    motor: list[m.Message | RawMessage] = [
        m.GetMotor(rng.randrange(8)), m.SetWheelSpeeds(100, 0, 0, 0), m.SetLiftSpeeds(0, 50),
        m.Run(rng.randrange(7), 300), m.Move(rng.randrange(7), 100, rng.choice([0, 500])),
        m.Stop(rng.choice([0x0F, 0x40])), m.Brake(0x3F)]
    foreign: list[m.Message | RawMessage] = [
        sim.StepTo(rng.randrange(10**6)), sim.GetTruth(), m.Ack(0x12, 0), RawMessage(0x55, b"\x01")]
    kinds: list[Callable[[], m.Message | RawMessage]] = [
        lambda: m.Identify(), lambda: m.GetStatus(), lambda: m.Heartbeat(rng.randrange(256)),
        lambda: m.ReadAll(), lambda: m.ReadAll(), lambda: m.ReadAll(), lambda: m.ReadAll(),
        lambda: m.GetSensor(rng.randrange(channels)), lambda: m.GetSensor(rng.randrange(8)),
        lambda: m.GetImu(rng.randrange(2)), lambda: m.GetImu(rng.randrange(4)),
        lambda: m.Clear(rng.choice([1, 2, 4, 7, 7])),
        lambda: m.Claim(rng.choice([0, 200, 1000, 1000]), rng.choice([1, 1, 2])),
        lambda: m.SetWatchdog(rng.choice([0, 0, 100, 250]), rng.choice([0, 0, 60])),
        lambda: m.EStop() if rng.random() < 0.3 else m.GetStatus(),
        lambda: rng.choice(motor), lambda: rng.choice(foreign),
    ]
    return rng.choice(kinds)()


def next_readings(rng: random.Random, prev: Readings, t_ms: int, modes: list[str]) -> Readings:
    """The plant at t_ms (> prev.now_ms): each channel (and the IMU, the last
    mode) measures anew, stalls or has never measured, by its mode, which
    changes now and then.  New measurements fall between the last instant
    and this one, some exactly half a millisecond off the clock (a tie the
    ages round) and some a microsecond after the last (a new sample all the
    same); codes, distances, angles and rates reach their edges."""
    now_us, prev_us = t_ms * 1000, prev.now_ms * 1000

    def when(last: int | None) -> int:
        if last is not None and last < now_us and rng.random() < 0.1:
            return last + 1
        if rng.random() < 0.15 and now_us >= 500:
            return now_us - 500 - 1000 * rng.randrange(min(5, now_us // 1000 + 1))
        return rng.randint(max(prev_us + 1, now_us - 50_000), now_us)

    for i in range(len(modes)):
        if rng.random() < 0.03:
            modes[i] = rng.choice(["live", "live", "live", "stalled", "none"])
    ranges = list(prev.ranges)
    for ch, mode in enumerate(modes[:-1]):
        if mode == "none":
            ranges[ch] = None
        elif mode == "live" and rng.random() < 0.7:
            last = ranges[ch]
            mm = rng.choice([0, 65535, rng.randrange(65536), rng.randrange(4000)])
            ranges[ch] = (rng.choice([0, 0, 0, 0, 1, 2]), mm, when(last[2] if last else None))
    imu = prev.imu
    if modes[-1] == "none":
        imu = None
    elif modes[-1] == "live" and rng.random() < 0.8:
        us = when(imu[0][3] if imu else None)

        def axis() -> Axis:
            cdeg = rng.randint(-18000, 18000) if rng.random() < 0.9 else rng.choice(
                [18001, -18001, 32767, -32768])
            return (rng.choice([0] * 6 + [2]), cdeg, rng.choice(
                [rng.randint(-32768, 32767), -32768, 32767, 0]), us)
        imu = [axis(), axis()]
    return Readings(t_ms, ranges, imu)


class RepliesDiffer(AssertionError):
    """A reply frame of the C board and the fake's differ: (frame index, time, C's, the fake's)."""


@dataclasses.dataclass
class Script:
    """The frames of two hosts and the readings before each."""

    frames: list[tuple[Readings, bytes]]
    commands: list[str]


def make_script(seed: int, channels: int, count: int) -> Script:
    """count frames of two hosts (sessions 7 and 9, each with its own
    sequence numbers, a tenth sent again as a retry is, a fiftieth to the
    motor board), the clock moving between them and the readings with it,
    and sbsensor's commands for all of it."""
    rng = random.Random(seed)
    now = Readings(0, [None] * channels, None)
    modes = ["none"] * (channels + 1)  # every channel and the IMU: never measured, absent
    seqs, last = {7: 0, 9: 0}, {7: b"", 9: b""}
    frames, commands = [], []
    for _ in range(count):
        dt = rng.choice([0, 1, 3, 10, 30, 60, 100, 120, 250, 400])  # 100, 250: on a watchdog
        if rng.random() < 0.004:
            dt = rng.choice([65_535, 66_000, 70_000])  # ages past saturation
        if dt:
            now = next_readings(rng, now, now.now_ms + dt, modes)
            commands.append(f"t {now.now_ms}")
            for ch, r in enumerate(now.ranges):
                commands.append(f"range {ch} none" if r is None
                                else f"range {ch} {r[0]} {r[1]} {r[2]}")
            for ax, a in enumerate(now.imu or []):
                commands.append(f"imu {ax} {a[0]} {a[1]} {a[2]} {a[3]}")
            if now.imu is None:
                commands.append("imu none")
        session = rng.choice([7, 7, 7, 9])
        if last[session] and rng.random() < 0.1:
            wire = last[session]  # a retry: the same bytes
        else:
            seqs[session] = (seqs[session] + 1) & 0xFF
            if rng.random() < 0.02:  # more replies than a frame holds: the rest left off
                msgs: tuple[m.Message | RawMessage, ...] = (m.ReadAll(),) * 4 + (m.Identify(),)
            else:
                msgs = tuple(random_request(rng, channels) for _ in range(rng.choice([1, 1, 2, 3])))
            board = m.Board.MOTOR if rng.random() < 0.02 else SENSOR  # another board's: no reply
            wire = encode_frame(Frame(board, seqs[session], msgs, session=session))
        last[session] = wire
        commands.append(f"w {wire.hex()}")
        frames.append((now, wire))
    return Script(frames, commands)


def run_c(exe: Path, boot: int, channels: int, flags: list[str], script: Script) -> list[str]:
    """sbsensor's answers to the script's frames, in order."""
    with subprocess.Popen([str(exe), str(boot), str(channels), *flags], stdin=subprocess.PIPE,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as proc:
        out, err = proc.communicate("".join(c + "\n" for c in script.commands), timeout=120)
    assert proc.returncode == 0 and not err, err  # no sanitizer report
    lines = out.splitlines()
    assert len(lines) == len(script.commands)
    assert not [x for x in lines if x.startswith("err")]
    return [a for c, a in zip(script.commands, lines, strict=True) if c.startswith("w ")]


def compare(script: Script, answers: list[str], channels: int, flags: list[str],
            boot: int) -> tuple[set[str], int]:
    """Replays the script on the Python fake behind its server and asserts
    every reply frame equal to the C board's field by field, but where the
    fake rounds a float: Owner.lease_cs within 1 (as in the motor board's
    test) and an age whose exact value lies half way between two
    milliseconds (the fake rounds age_s + 0.0, a float, which lands on
    either side of the half; the C board rounds the exact microseconds half
    to even, which this asserts).  Returns what the replies reached and the
    duplicates the fake's cache answered."""
    robot = ScriptedSensors(channels)
    world = BoardWorld(robot, ScriptedClock(robot), side_pair=channels == 6)  # type: ignore[arg-type]
    fake = SensorBoard(world, serial=2)
    fake.boot = fake.lease.boot = boot
    ours, theirs = socket.socketpair()
    server = SerialBoardServer(ours.fileno(), world, {int(SENSOR): fake})
    theirs.setblocking(False)
    seen: set[str] = set()
    built = Readings(0, [], None)  # the readings the kept reply was built from
    try:
        for i, ((now, wire), c_hex) in enumerate(zip(script.frames, answers, strict=True)):
            robot.now = Readings(now.now_ms, [None] * channels if "norange" in flags
                                 else list(now.ranges), None if "noimu" in flags else now.imu)
            fake.poll()
            rx, duplicates = server.stats.frames_rx, server.stats.duplicates
            server.receive(wire)
            if server.stats.frames_rx > rx and server.stats.duplicates == duplicates:
                built = robot.now  # a new reply, kept for the retries
            py = theirs.recv(4096) if select.select([theirs], [], [], 0)[0] else b""
            c = b"" if c_hex == "-" else bytes.fromhex(c_hex)
            c_frames, py_frames = FrameReader().feed(c), FrameReader().feed(py)
            if len(c_frames) != len(py_frames):
                raise RepliesDiffer(i, now.now_ms, c_frames, py_frames)
            for cf, pf in zip(c_frames, py_frames, strict=True):
                if (len(cf.messages) != len(pf.messages) or dataclasses.replace(
                        cf, messages=()) != dataclasses.replace(pf, messages=())):
                    raise RepliesDiffer(i, now.now_ms, cf, pf)
                for cm, pm in zip(cf.messages, pf.messages, strict=True):
                    if not alike(cm, pm, built):
                        raise RepliesDiffer(i, now.now_ms, cm, pm)
                    seen.update(reached(cm, built))
                asked = FrameReader().feed(wire)[0].messages
                if len(cf.messages) < sum(channels + 3 if isinstance(x, m.ReadAll) else 1
                                          for x in asked):
                    seen.add("cut")
    finally:
        ours.close()
        theirs.close()
    return seen, server.stats.duplicates


def half_even(us: int) -> int:
    ms, rest = divmod(us, 1000)
    return ms + (rest > 500 or (rest == 500 and ms % 2 == 1))


def alike(c: m.Message | RawMessage, py: m.Message | RawMessage, built: Readings) -> bool:
    """Whether two replies are the same, within the tolerances compare() names."""
    if isinstance(c, m.Owner) and isinstance(py, m.Owner):
        return abs(c.lease_cs - py.lease_cs) <= 1 and dataclasses.replace(
            c, lease_cs=0) == dataclasses.replace(py, lease_cs=0)
    if (isinstance(c, m.SensorTelemetry | m.ImuTelemetry) and type(c) is type(py)
            and c.age_ms != py.age_ms):
        exact = built.age_us(c)
        return (exact is not None and exact % 1000 == 500 and exact < m.AGE_MAX_MS * 1000
                and c.age_ms == half_even(exact) and abs(c.age_ms - py.age_ms) == 1
                and dataclasses.replace(c, age_ms=0) == dataclasses.replace(py, age_ms=0))
    return c == py


def reached(msg: m.Message | RawMessage, built: Readings) -> set[str]:
    """What a reply shows the script reached."""
    if isinstance(msg, m.SensorTelemetry | m.ImuTelemetry):
        kind = "sensor" if isinstance(msg, m.SensorTelemetry) else "imu"
        code = (m.SensorCode if kind == "sensor" else m.ImuCode)(msg.status).name
        exact = built.age_us(msg)
        out = {f"{kind} {code}"}
        if exact is None and kind == "sensor":
            out.add("sensor never measured")
        elif exact is not None and msg.age_ms == m.AGE_MAX_MS:
            out.add(f"{kind} age saturated")
        elif exact is not None and exact % 1000 == 500:
            out.add("age tie")
        if isinstance(msg, m.ImuTelemetry) and abs(msg.rate_ddps) == m.INT16_MAX:
            out.add("imu rate at its limit")
        return out
    return reached_by_any_board(msg)


SEEDS = [(4, 45, 4000, []), (6, 46, 4000, ["nous"]), (6, 47, 400, ["norange", "noimu"])]


@pytest.fixture(scope="module")
def sbsensor(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """sbsensor built with AddressSanitizer and UBSan, once for the runs."""
    return build(tmp_path_factory.mktemp("sbsensor") / "sbsensor", ("core", "board"),
                 ("test/sbline.c", "test/sbsensor.c"), ["-O1", "-g", *SANITIZE])


@pytest.mark.parametrize(("channels", "seed", "count", "flags"), SEEDS)
def test_the_c_sensor_board_answers_as_the_python_fake_step_by_step(
        sbsensor: Path, channels: int, seed: int, count: int, flags: list[str]) -> None:
    """The C board built with AddressSanitizer and UBSan (no report), four
    and six channels, and thousands of frames of two hosts (sessions 7 and
    9, a tenth of them retries, a fiftieth to the motor board, which the
    sensor board does not answer), the clock moving 0 to 400 ms between
    them and now and then past an age's saturation, the readings changing
    with it: every reply frame alike (compare() names the two tolerances);
    and the script reaches what it is meant to (retries answered from the
    cache, every Ack and Claim result a sensor board gives, both latches,
    every SensorCode and ImuCode, readings never measured, ages saturated
    and ages on a tie, reply frames cut at 247 message bytes).  The third
    run's HAL has neither range_read nor imu_read (and the second none of
    now_us: the board counts now_ms * 1000)."""
    boot = 0x5E45
    script = make_script(seed, channels, count)
    seen, duplicates = compare(script, run_c(sbsensor, boot, channels, flags, script), channels,
                               flags, boot)
    assert duplicates > count // 40
    wanted = {"ack NOT_OWNER", "ack NOT_SUPPORTED", "ack BAD_CHANNEL", "ack UNKNOWN_TYPE",
              "estop", "watchdog", "imu ABSENT", "sensor ERROR", "sensor never measured", "cut"}
    wanted |= {f"claim {r.name}" for r in m.ClaimResult}
    if not flags or flags == ["nous"]:
        wanted |= {"sensor OK", "sensor OUT_OF_RANGE", "sensor age saturated", "age tie",
                   "imu OK", "imu ERROR", "imu age saturated", "imu rate at its limit"}
    assert wanted <= seen, wanted - seen


MUTANTS = {
    "an age truncated, not rounded": (
        "if (rest > 500u || (rest == 500u && (ms & 1u))) ms++;", "(void)rest;"),
    "a sample counted on every read": (
        "if (!s->seen || s->measured_us != measured_us) {", "if (true) {"),
    "an angle beyond 180 degrees sent": ("s.code == SB_IMU_OK && (", "false && ("),
    "a stalled reading's age saturated early": (
        "sb_board_since(b, s->new_ms) > SB_AGE_MAX_MS", "sb_board_since(b, s->new_ms) > 1000"),
}


@pytest.mark.parametrize("mutant", sorted(MUTANTS))
def test_a_mutant_of_the_c_sensor_board_fails_the_comparison(tmp_path: Path, mutant: str) -> None:
    """sb_sensor.c with one change the comparison must catch: the first
    1,500 frames of the four-channel run's script find it."""
    old, new = MUTANTS[mutant]
    source = (FIRMWARE / "board" / "sb_sensor.c").read_text()
    assert source.count(old) == 1, old
    mutated = tmp_path / "sb_sensor.c"
    mutated.write_text(source.replace(old, new))
    exe = build(tmp_path / "sbsensor", ("core",), ("board/sb_board.c", str(mutated),
                                                    "test/sbline.c", "test/sbsensor.c"), ["-O1"])
    channels, seed, _, flags = SEEDS[0]
    script = make_script(seed, channels, 1500)
    with pytest.raises(RepliesDiffer):
        compare(script, run_c(exe, 0x5E45, channels, flags, script), channels, flags, 0x5E45)
