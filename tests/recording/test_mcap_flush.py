"""The MCAP writer's flushes, on a clock the test turns: what a file holds
while its writer still runs is what a kill at that moment would leave."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from stairbot.control.robot_config import load_config
from stairbot.errors import InputError
from stairbot.events import Event, EventKind
from stairbot.hardware import BASE_SENSORS, Imu, MotorId, MotorState, SensorReading, Snapshot
from stairbot.recording import topics
from stairbot.recording.mcap_sink import FLUSH_PERIOD_S, FLUSH_TICKS, McapRecord
from stairbot.recording.read import read_recording
from stairbot.recording.stream import AppendStream

CONFIG = load_config(None)


class Wall:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def snap(i: int) -> Snapshot:
    return Snapshot(time_s=i * 0.02,
                    sensors={s: SensorReading(0.5) for s in BASE_SENSORS},
                    motors={m: MotorState(turns=i * 0.01) for m in MotorId},
                    imu=Imu(pitch_deg=0.0, roll_deg=0.0))


def kept(path: Path) -> int:
    return read_recording(path).counts[topics.SENSORS]


@pytest.fixture
def started(tmp_path: Path) -> tuple[McapRecord, Wall, Path]:
    wall = Wall()
    path = tmp_path / "r.mcap"
    record = McapRecord(path, CONFIG, wall=wall)
    record.write(Event(0.0, EventKind.INFO, "start"))
    record.flush()
    return record, wall, path


def test_every_flush_ticks_without_the_wall_clock_moving(
        started: tuple[McapRecord, Wall, Path]) -> None:
    record, _wall, path = started
    for i in range(100):
        record.tick(snap(i), {MotorId.MWF: 1.0})
    assert kept(path) == 0  # in the chunk in progress: a kill now loses them
    for i in range(100, FLUSH_TICKS):  # a chunk grown to CHUNK_BYTES is written out too
        record.tick(snap(i), None)
    assert kept(path) == FLUSH_TICKS
    for i in range(FLUSH_TICKS, FLUSH_TICKS + 10):
        record.tick(snap(i), None)
    assert kept(path) == FLUSH_TICKS
    record.close()
    rec = read_recording(path)
    assert rec.complete and rec.counts[topics.SENSORS] == FLUSH_TICKS + 10


def test_every_flush_period_of_wall_time(started: tuple[McapRecord, Wall, Path]) -> None:
    record, wall, path = started
    record.tick(snap(0), None)
    wall.now += FLUSH_PERIOD_S * 0.9
    record.tick(snap(1), None)
    assert kept(path) == 0
    wall.now += FLUSH_PERIOD_S * 0.2
    record.tick(snap(2), None)
    assert kept(path) == 3
    record.write(Event(0.06, EventKind.WARNING, "late"))
    assert [e["message"] for e in read_recording(path).events] == ["start"]
    wall.now += FLUSH_PERIOD_S
    record.write(Event(0.06, EventKind.WARNING, "later"))
    assert [e["message"] for e in read_recording(path).events] == ["start", "late", "later"]
    record.close()


def test_the_stream_only_appends(tmp_path: Path) -> None:
    stream = AppendStream(tmp_path / "s.bin")
    assert stream.write(b"abc") == 3
    assert stream.seek(0, io.SEEK_CUR) == 3 and stream.seek(3) == 3
    for offset, whence in ((0, io.SEEK_SET), (-1, io.SEEK_CUR), (0, io.SEEK_END)):
        with pytest.raises(OSError, match="cannot seek"):
            stream.seek(offset, whence)
    stream.close()
    assert (tmp_path / "s.bin").read_bytes() == b"abc"
    with pytest.raises(InputError, match="cannot write the record"):
        AppendStream(tmp_path / "missing" / "s.bin")
