"""``stairbot run --foxglove``: a simulated run paced to the wall clock,
watched by a WebSocket client that speaks the Foxglove WebSocket protocol
(aiohttp's client): the server's info, the channels it advertises -- the
MCAP record's topics with the same schema names -- and the live messages of
the topics it subscribes to, decoded (JSON, and protobuf with the schema
the server advertised).  Then Ctrl-C ends the run, and the server with it.
Bad addresses: one line, exit 2, nothing run."""

from __future__ import annotations

import asyncio
import base64
import json
import os
import re
import signal
import socket
import struct
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import aiohttp
import pytest
from mcap.reader import make_reader
from mcap.records import Schema
from mcap_protobuf.decoder import DecoderFactory

from stairbot.cli import main
from stairbot.cli.common import EXIT_INPUT, EXIT_INTERRUPTED
from stairbot.hardware import MotorId, SensorStatus
from stairbot.recording import topics

PROTOCOL = "foxglove.sdk.v1"
"""The subprotocol foxglove-sdk's server speaks (the Foxglove app offers it)."""
POSE = "/sim/true_pose"
LIVE_TOPICS = {topics.SCENE: "foxglove.SceneUpdate", topics.JOINTS: "foxglove.JointStates",
               topics.MOTORS: "stairbot.Motors", topics.SENSORS: "stairbot.Sensors",
               topics.LINK: "stairbot.Link", topics.EVENTS: "foxglove.Log",
               topics.PHASE: "foxglove.Log", topics.RECORD: "stairbot.Event",
               POSE: "foxglove.FrameTransforms"}
WATCHED = (topics.SCENE, topics.JOINTS, topics.MOTORS, topics.SENSORS, POSE)
WAIT_S = 120.0  # a hang guard only: each wait ends as soon as its message comes
URL_LINE = re.compile(r"Foxglove live at (ws://\S+)")


class Run:
    """``stairbot run --foxglove 127.0.0.1:0`` in a process of its own, and
    the ws:// URL it printed."""

    def __init__(self, args: list[str]) -> None:
        env = {**os.environ, "PYTHONUNBUFFERED": "1"}
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "stairbot", "run", "--foxglove", "127.0.0.1:0", *args],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
        assert self.proc.stderr is not None
        self.said: list[str] = []
        for line in self.proc.stderr:
            self.said.append(line)
            found = URL_LINE.search(line)
            if found:
                self.url = found.group(1)
                break
        else:
            raise AssertionError("no Foxglove URL: " + "".join(self.said))

    def interrupt(self) -> int:
        """Ctrl-C: the run ends (the robot stopped), and its server."""
        self.proc.send_signal(signal.SIGINT)
        _out, err = self.proc.communicate(timeout=WAIT_S)
        self.said.append(err)
        return self.proc.returncode


@pytest.fixture
def running(tmp_path: Path) -> Iterator[Callable[[list[str]], Run]]:
    runs: list[Run] = []

    def start(args: list[str]) -> Run:
        runs.append(Run(args))
        return runs[-1]

    yield start
    for run in runs:  # a failed test still ends its run
        if run.proc.poll() is None:
            run.proc.kill()
            run.proc.wait()


async def _watch(url: str, protocol: str) -> dict[str, Any]:
    """Connect to the server, read its info and advertisements until every
    topic is there, subscribe to WATCHED, and keep the first messages of each."""
    got: dict[str, Any] = {"channels": {}, "messages": {}}
    async with aiohttp.ClientSession() as session, session.ws_connect(
            url, protocols=[protocol]) as ws:
        got["protocol"] = ws.protocol
        while set(LIVE_TOPICS) - set(got["channels"]):
            msg = await ws.receive(timeout=WAIT_S)
            assert msg.type is aiohttp.WSMsgType.TEXT, msg
            data = json.loads(msg.data)
            if data["op"] == "serverInfo":
                got["server"] = data
            elif data["op"] == "advertise":
                for channel in data["channels"]:
                    assert channel["topic"] not in got["channels"], channel["topic"]
                    got["channels"][channel["topic"]] = channel
        by_id = dict(enumerate(WATCHED, start=1))
        await ws.send_str(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": sub, "channelId": got["channels"][topic]["id"]}
            for sub, topic in by_id.items()]}))
        messages: dict[str, list[tuple[int, bytes]]] = got["messages"]
        while any(len(messages.get(t, [])) < (1 if t == topics.SCENE else 3) for t in WATCHED):
            msg = await ws.receive(timeout=WAIT_S)
            if msg.type is aiohttp.WSMsgType.TEXT:  # a status is a refusal: said at once
                assert json.loads(msg.data)["op"] != "status", msg.data
                continue
            assert msg.type is aiohttp.WSMsgType.BINARY, msg
            opcode, sub, log_time = struct.unpack_from("<BIQ", msg.data)
            assert opcode == 1  # messageData
            messages.setdefault(by_id[sub], []).append((log_time, msg.data[13:]))
    return got


def _protobuf(channel: dict[str, Any]) -> Callable[[bytes], Any]:
    """A decoder for a protobuf channel, from the schema the server advertised."""
    assert channel["encoding"] == "protobuf" and channel["schemaEncoding"] == "protobuf"
    schema = Schema(id=1, name=channel["schemaName"], encoding="protobuf",
                    data=base64.b64decode(channel["schema"]))
    decoder = DecoderFactory().decoder_for("protobuf", schema)
    assert decoder is not None
    return decoder


def _mcap_channels(path: Path) -> tuple[dict[str, str], int]:
    """The record's topics with their schema names, and its /scene messages."""
    with path.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None and summary.statistics is not None
    names = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
    scenes = sum(n for cid, n in summary.statistics.channel_message_counts.items()
                 if summary.channels[cid].topic == topics.SCENE)
    return names, scenes


def _port_closed(url: str) -> bool:
    host, port = url.removeprefix("ws://").rsplit(":", 1)
    try:
        socket.create_connection((host, int(port)), timeout=5).close()
    except ConnectionRefusedError:
        return True
    return False


def test_a_client_sees_the_record_topics_live(
        running: Callable[[list[str]], Run], tmp_path: Path) -> None:
    record = tmp_path / "run.mcap"
    run = running(["--record", str(record)])
    assert run.url.startswith("ws://127.0.0.1:")
    got = asyncio.run(_watch(run.url, PROTOCOL))
    assert run.interrupt() == EXIT_INTERRUPTED  # the run was live while the client watched
    assert _port_closed(run.url)  # the server ended with the run

    assert got["protocol"] == PROTOCOL
    assert got["server"]["name"] == "stairbot"
    assert got["server"]["capabilities"] == []  # the stream takes no commands
    advertised = {t: c["schemaName"] for t, c in got["channels"].items()}
    assert advertised == LIVE_TOPICS
    names, scenes = _mcap_channels(record)
    assert advertised == names  # the record's topics, the same schemas
    assert scenes == 1  # the scene sent again to the client stayed out of the record
    for topic in (topics.MOTORS, topics.SENSORS, topics.LINK, topics.RECORD):
        assert got["channels"][topic]["encoding"] == "json"
        assert json.loads(got["channels"][topic]["schema"])["title"] == LIVE_TOPICS[topic]

    motors = [json.loads(data) for _t, data in got["messages"][topics.MOTORS]]
    times = [m["time_s"] for m in motors]
    assert times == sorted(times) and times[0] < times[-1]  # ticks, in order
    assert {m.value for m in MotorId} <= set(motors[-1])
    assert all(isinstance(m["MWF"]["turns"], float) for m in motors)
    sensors = json.loads(got["messages"][topics.SENSORS][-1][1])
    assert {"SFR", "SFL", "SBR", "SBL", "imu"} <= set(sensors)
    assert sensors["SFR"]["status"] in {s.value for s in SensorStatus}

    joints = _protobuf(got["channels"][topics.JOINTS])(got["messages"][topics.JOINTS][-1][1])
    assert [j.name for j in joints.joints] == [m.value for m in MotorId]
    pose = _protobuf(got["channels"][POSE])(got["messages"][POSE][-1][1])
    assert [t.child_frame_id for t in pose.transforms] == ["segment1", "segment2", "segment3"]
    # the client connected after the robot was opened, and still got the scene
    scene = _protobuf(got["channels"][topics.SCENE])(got["messages"][topics.SCENE][0][1])
    assert "stairs" in {e.id for e in scene.entities}


def test_without_a_record_the_same_topics_stream(running: Callable[[list[str]], Run]) -> None:
    run = running(["-q"])
    got = asyncio.run(_watch(run.url, PROTOCOL))
    # the SDK's server speaks foxglove.sdk.v1 alone (docs/recording.md says which apps do)
    with pytest.raises(aiohttp.WSServerHandshakeError, match="400"):
        asyncio.run(_watch(run.url, "foxglove.websocket.v1"))
    assert run.interrupt() == EXIT_INTERRUPTED
    assert {t: c["schemaName"] for t, c in got["channels"].items()} == LIVE_TOPICS
    sensors = [json.loads(data)["time_s"] for _t, data in got["messages"][topics.SENSORS]]
    assert sensors == sorted(sensors) and sensors[0] < sensors[-1]


@pytest.mark.parametrize(("given", "said"), [
    ("x:y", "PORT must be a number from 0 to 65535"),
    ("70000", "PORT must be a number from 0 to 65535"),
    (":8765", "HOST is empty"),
    ("::1:8765", "write an IPv6 address in brackets"),
    ("no-such-host.invalid:8765", "cannot resolve HOST"),
    ("192.0.2.1:8765", "the address is not one of this machine's"),
])
def test_a_bad_address_is_one_line_and_nothing_runs(
        given: str, said: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "--foxglove", given]) == EXIT_INPUT
    out, err = capsys.readouterr()
    assert out == ""  # no run: no progress, no summary
    assert err.count("\n") == 1 and "--foxglove" in err and said in err, err


@pytest.mark.parametrize("command", [["run"], ["console"]])
def test_a_port_in_use_is_refused(command: list[str],
                                  capsys: pytest.CaptureFixture[str]) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        assert main([*command, "--foxglove", str(port)]) == EXIT_INPUT
    out, err = capsys.readouterr()
    assert out == ""
    assert err.count("\n") == 1 and f"127.0.0.1:{port}" in err and "the port is in use" in err


@pytest.mark.parametrize("other", [["--serve", "8000"], ["--replay", "run.mcap"]])
def test_the_console_refuses_foxglove_with_serve_or_replay(
        other: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["console", *other, "--foxglove"]) == EXIT_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--foxglove" in err
