"""The side pair SSR/SSL in recordings: an MCAP record carries them when the
snapshot has them (optional fields of the sensors' schema), the reader, the
replay and the plot read them back; a robot without the pair records the
four base sensors alone, as every recording made before the pair existed
did, and such a recording still replays.  A JSON-lines record holds events
alone: what an event says of the side pair comes back as it was written."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import pytest

from stairbot.control.algorithm import limits
from stairbot.control.robot_config import load_config, parse_config
from stairbot.events import Event, EventKind
from stairbot.hardware import (
    BASE_SENSORS,
    SIDE_SENSORS,
    Imu,
    MotorId,
    MotorState,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
)
from stairbot.inputs.config import RobotConfig
from stairbot.recording import topics
from stairbot.recording.mcap_sink import McapRecord
from stairbot.recording.read import read_recording
from stairbot.recording.record import JsonLinesRecord
from stairbot.recording.replay_load import load_replay

SIDE_CONFIG: RobotConfig = parse_config(
    'extends = "reference"\n[sensors]\nside_model = "vl53l0x"\n', "side.toml")
TICKS = 20


def snap(i: int, side_pair: bool) -> Snapshot:
    sensors = {s: SensorReading(0.3 + i / 1000, age_s=0.004) for s in BASE_SENSORS}
    if side_pair:
        sensors[SensorId.SSR] = SensorReading(0.62 + i / 1000, age_s=0.031)
        sensors[SensorId.SSL] = SensorReading(1.3, SensorStatus.OUT_OF_RANGE, 0.031)
    return Snapshot(i * 0.02, sensors, {m: MotorState(i * 0.01) for m in MotorId},
                    imu=Imu(1.0, 0.0))


def record(path: Path, config: RobotConfig, side_pair: bool) -> Path:
    rec = McapRecord(path, config)
    rec.write(Event(0.0, EventKind.INFO, "start"))
    for i in range(TICKS):
        rec.tick(snap(i, side_pair), {MotorId.MWF: 0.5})
    rec.close()
    return path


def sensor_messages(path: Path) -> list[dict[str, Any]]:
    from mcap.reader import make_reader

    with path.open("rb") as f:
        return [json.loads(msg.data) for _, channel, msg in make_reader(f).iter_messages()
                if channel.topic == topics.SENSORS]


def required_of(schema: dict[str, Any]) -> set[str]:
    return set(schema["required"])


def test_the_schema_has_the_side_pair_as_optional_fields() -> None:
    schema = topics.SENSORS_SCHEMA
    assert {s.value for s in SensorId} <= set(schema["properties"])
    assert required_of(schema) == {"time_s", "imu", *(s.value for s in BASE_SENSORS)}


@pytest.mark.parametrize("side_pair", [True, False], ids=["with", "without"])
def test_an_mcap_record_carries_the_side_pair_when_the_snapshot_has_it(
        tmp_path: Path, side_pair: bool) -> None:
    path = record(tmp_path / "r.mcap", SIDE_CONFIG if side_pair else load_config(), side_pair)
    messages = sensor_messages(path)
    assert len(messages) == TICKS
    for m in messages:  # each message holds what its schema requires, and no more
        assert required_of(topics.SENSORS_SCHEMA) <= set(m) <= set(
            topics.SENSORS_SCHEMA["properties"])
        assert ("SSR" in m and "SSL" in m) is side_pair and ("SSR" in m or "SSL" in m) is side_pair
    if side_pair:
        assert messages[3]["SSR"] == {"distance_m": 0.623, "status": "ok", "age_s": 0.031}
        assert messages[3]["SSL"]["status"] == "out_of_range"
    # the reader (stairbot plot)
    tel = read_recording(path).telemetry
    assert set(tel.distance_m) == {s.value for s in BASE_SENSORS + (SIDE_SENSORS if side_pair
                                                                     else ())}
    if side_pair:
        assert tel.distance_m["SSR"][3] == 0.623 and tel.status["SSL"][0] == "out_of_range"


@pytest.mark.parametrize("side_pair", [True, False], ids=["with", "without"])
def test_the_replay_reads_the_side_pair_back_or_nothing_of_it(
        tmp_path: Path, side_pair: bool) -> None:
    path = record(tmp_path / "r.mcap", SIDE_CONFIG if side_pair else load_config(), side_pair)
    source = load_replay(path)
    assert source.config is not None and source.config.sensors.has_side_pair is side_pair
    snaps = [t.snapshot for t in source.ticks]
    assert len(snaps) == TICKS and all(s is not None for s in snaps)
    for i, got in enumerate(snaps):
        assert got is not None
        want = snap(i, side_pair)
        assert set(got.sensors) == set(want.sensors)
        for sensor, reading in want.sensors.items():
            assert got.sensors[sensor].status is reading.status
            assert got.sensors[sensor].distance_m == pytest.approx(reading.distance_m)
            assert got.sensors[sensor].age_s == pytest.approx(reading.age_s)


def test_a_recording_made_before_the_side_pair_still_replays(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Its schema names the four sensors, each required; its config has no
    side_model key at all."""
    old = copy.deepcopy(topics.SENSORS_SCHEMA)
    for s in SIDE_SENSORS:
        del old["properties"][s.value]
    old["required"] = ["time_s", *(s.value for s in BASE_SENSORS), "imu"]
    monkeypatch.setattr(topics, "SENSORS_SCHEMA", old)
    original = limits.config_dict

    def without_side_keys(config: RobotConfig) -> dict[str, Any]:
        d = original(config)
        d["sensors"] = {k: v for k, v in d["sensors"].items() if not k.startswith("side_")}
        return d

    monkeypatch.setattr(limits, "config_dict", without_side_keys)
    path = record(tmp_path / "old.mcap", load_config(), side_pair=False)
    attached = json.loads(read_recording(path).attachments["robot_config.json"])
    assert not any(k.startswith("side_") for k in attached["sensors"])
    source = load_replay(path)
    assert source.config is not None and not source.config.sensors.has_side_pair
    first = source.ticks[0].snapshot
    assert first is not None and set(first.sensors) == set(BASE_SENSORS)


def test_the_plot_has_a_side_panel_only_for_a_recording_with_the_pair(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    from stairbot.recording.plot import render

    def height(data: bytes) -> int:
        return int.from_bytes(data[20:24], "big")  # the PNG's IHDR

    with_pair = render(read_recording(record(tmp_path / "a.mcap", SIDE_CONFIG, True)))
    without = render(read_recording(record(tmp_path / "b.mcap", load_config(), False)))
    assert height(without) == 1210  # six panels of 2.2 in at 100 dpi, the strip half
    assert height(with_pair) == 1210 + 220  # and the side sensors' own


def test_a_json_lines_record_gives_back_what_an_event_said_of_the_side_pair(
        tmp_path: Path) -> None:
    path = tmp_path / "events.jsonl"
    rec = JsonLinesRecord(path)
    said = {"SSR": {"distance_m": 0.62, "status": "ok"}, "SSL": {"distance_m": 1.3,
                                                             "status": "out_of_range"}}
    rec.write(Event(1.5, EventKind.INFO, "landing: looked sideways", "landing", said))
    rec.close()
    source = load_replay(path)
    assert [e.data for e in source.events] == [said]
    assert read_recording(path).events[0]["data"] == said
