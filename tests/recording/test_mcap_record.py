"""A default run recorded as MCAP (issue 12, item 1), read back with the
``mcap`` package's own reader: every channel there, one message a tick on
the tick channels, one log an event, the attachments and the metadata."""

from __future__ import annotations

import json
import math
from collections import Counter
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any

import pytest
from mcap.decoder import DecoderFactory as McapDecoderFactory
from mcap.reader import make_reader
from mcap.records import Schema
from mcap_protobuf.decoder import DecoderFactory

from stairbot.cli import main
from stairbot.control.algorithm import limits
from stairbot.control.robot_config import load_config
from stairbot.recording import topics
from stairbot.recording.pose import SEGMENT_FRAMES

TICK_S = load_config(None).algorithm.tick
TICK_CHANNELS = {topics.JOINTS: "foxglove.JointStates", topics.MOTORS: "stairbot.Motors",
                 topics.SENSORS: "stairbot.Sensors", topics.LINK: "stairbot.Link",
                 "/sim/true_pose": "foxglove.FrameTransforms"}


class JsonDecoders(McapDecoderFactory):
    """The JSON channels' messages as dicts."""

    def decoder_for(self, message_encoding: str,
                    schema: Schema | None) -> Callable[[bytes], Any] | None:
        return json.loads if message_encoding == "json" else None


@pytest.fixture(scope="module")
def default_run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The default run twice (the simulation is deterministic): to MCAP, and
    to JSON lines, with the result as --json prints it."""
    d = tmp_path_factory.mktemp("mcap")
    out: dict[str, Any] = {"mcap": d / "run.mcap", "jsonl": d / "run.jsonl"}
    for kind in ("mcap", "jsonl"):
        assert main(["run", "-q", "--record", str(out[kind])]) == 0
    return out


def _read(path: Path) -> tuple[Any, list[Any], list[Any], list[Any]]:
    with path.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory(), JsonDecoders()])
        summary = reader.get_summary()
        messages = list(reader.iter_decoded_messages(log_time_order=True))
        attachments = list(reader.iter_attachments())
        metadata = list(reader.iter_metadata())
    return summary, messages, attachments, metadata


def test_every_channel_with_one_message_a_tick_and_one_log_an_event(
        default_run: dict[str, Any]) -> None:
    summary, messages, _att, _meta = _read(default_run["mcap"])
    events = [json.loads(line) for line in default_run["jsonl"].read_text().splitlines()]
    end = events[-1]
    assert end["kind"] == "summary" and end["data"]["outcome"] == "completed"
    ticks = round(end["data"]["sim_time_s"] / TICK_S)
    assert ticks > 10000  # the whole default run, not a few ticks

    schemas = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
    counts = Counter({summary.channels[cid].topic: n
                      for cid, n in summary.statistics.channel_message_counts.items()})
    for topic, schema in TICK_CHANNELS.items():
        assert schemas[topic] == schema
        assert counts[topic] == ticks, topic
    assert schemas[topics.SCENE] == "foxglove.SceneUpdate" and counts[topics.SCENE] == 1
    assert schemas[topics.EVENTS] == schemas[topics.PHASE] == "foxglove.Log"
    assert counts[topics.EVENTS] == counts[topics.RECORD] == len(events)
    assert counts[topics.PHASE] == sum(e["kind"] == "phase" for e in events)
    assert "/robot/estimated_pose" not in schemas  # the simulation's pose, not an estimate
    assert summary.statistics.message_count == sum(counts.values())

    # the MCAP holds the JSON-lines record, line for line (but the wall clock's figures)
    recorded = [m.decoded_message for m in messages if m.channel.topic == topics.RECORD]
    assert [_steady(e) for e in recorded] == [_steady(e) for e in events]
    logs = [m.decoded_message for m in messages if m.channel.topic == topics.EVENTS]
    assert [log.message for log in logs] == [e["message"] for e in events]
    assert {log.name for log in logs} == {e["kind"] for e in events}
    phases = [m.decoded_message for m in messages if m.channel.topic == topics.PHASE]
    assert [p.message for p in phases] == [e["phase"] for e in events if e["kind"] == "phase"]
    assert {p.name for p in phases} == {"calibration", "ascent", "descent", "end"}


def _steady(event: dict[str, Any]) -> dict[str, Any]:
    """An event without what the wall clock decides (the summary's wall time)."""
    data = {k: v for k, v in event["data"].items() if k not in ("wall_time_s", "realtime_factor")}
    return {**event, "data": data}


def test_the_tick_messages_say_what_the_robot_did(default_run: dict[str, Any]) -> None:
    _summary, messages, _att, meta = _read(default_run["mcap"])
    origin = int(next(m for m in meta if m.name == "stairbot").metadata["time_origin_ns"])
    sensors = [m.decoded_message for m in messages if m.channel.topic == topics.SENSORS]
    motors = [m.decoded_message for m in messages if m.channel.topic == topics.MOTORS]
    poses = [m for m in messages if m.channel.topic == "/sim/true_pose"]
    # log time = origin + robot time, one tick apart
    first = next(m for m in messages if m.channel.topic == topics.SENSORS)
    assert first.message.log_time == origin + round(sensors[0]["time_s"] * 1e9)
    times = [s["time_s"] for s in sensors]
    assert all(math.isclose(b - a, TICK_S, abs_tol=1e-6)
               for a, b in zip(times, times[1:], strict=False))
    assert {"SFR", "SFL", "SBR", "SBL", "imu"} <= set(sensors[0])
    assert {s["SFR"]["status"] for s in sensors} >= {"ok"}
    # the lifts went up a step's rise and back (0.17 m), the wheels turned
    mtf = [m["MTF"]["extension_m"] for m in motors]
    assert 0.15 < max(mtf) < 0.21 and abs(mtf[-1]) < 0.01
    assert motors[-1]["MWF"]["turns"] != motors[0]["MWF"]["turns"]
    assert all(m["sent"] and m["MWF"]["command_tps"] is not None for m in motors[:100])
    # segment 2 climbed five 0.17 m steps and came home; the frames are the three segments
    heights = [next(t.translation.z for t in p.decoded_message.transforms
                    if t.child_frame_id == "segment2") for p in poses]
    assert heights[0] == pytest.approx(0.016, abs=0.005)  # the axle: a wheel's radius up
    # (lifted past the top tread by the drive clearance and the sight-over's lag)
    assert 0.016 + 5 * 0.17 - 0.005 < max(heights) < 0.016 + 5 * 0.17 + 0.02
    assert heights[-1] == pytest.approx(heights[0], abs=0.005)
    assert [t.child_frame_id for t in poses[0].decoded_message.transforms] == list(SEGMENT_FRAMES)
    assert {t.parent_frame_id for t in poses[0].decoded_message.transforms} == {"world"}


def test_attachments_metadata_and_scene(default_run: dict[str, Any]) -> None:
    _summary, messages, attachments, meta = _read(default_run["mcap"])
    by_name = {a.name: a for a in attachments}
    assert set(by_name) == set(topics.ATTACHMENTS)
    dbc = resources.files("stairbot").joinpath("drivers/stairbot.dbc").read_bytes()
    assert by_name["stairbot.dbc"].data == dbc
    assert json.loads(by_name["robot_config.json"].data) == json.loads(
        json.dumps(limits.config_dict(load_config(None))))
    scenario = json.loads(by_name["scenario.json"].data)
    assert scenario["name"] == "default" and len(scenario["steps"]) == 5
    robot = next(m for m in meta if m.name == "robot").metadata
    assert robot["url"] == "sim://" and robot["pose_topic"] == "/sim/true_pose"
    scene = next(m.decoded_message for m in messages if m.channel.topic == topics.SCENE)
    ids = [e.id for e in scene.entities]
    assert ids == ["stairs", *SEGMENT_FRAMES]
    stairs = scene.entities[0]
    tops = sorted(round(c.pose.position.z * 2, 3) for c in stairs.cubes)
    assert tops[-5:] == [0.17, 0.34, 0.51, 0.68, 0.85]  # a block per tread, the landing last
    for entity in scene.entities[1:]:
        assert entity.frame_locked and entity.frame_id == entity.id
        assert len(entity.cubes) == 1 and len(entity.cylinders) == 4  # the body, four wheels


def test_the_json_lines_record_is_unchanged(default_run: dict[str, Any]) -> None:
    lines = default_run["jsonl"].read_text().splitlines()
    assert all(set(json.loads(line)) == {"time_s", "kind", "phase", "message", "data"}
               for line in lines)
    assert not default_run["jsonl"].read_bytes().startswith(b"\x89MCAP")
