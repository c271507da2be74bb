"""``stairbot console --foxglove``: the console's runs streamed live by
foxglove-sdk's server.  A client that connects to an idle console gets the
scene of the robot it opened; a run's ticks stream; an MCAP record started
with `w` mid-run shares the server's channels, and every tick still
reaches the client once (never twice, never skipped for the record)."""

from __future__ import annotations

import asyncio
import json
import struct
from pathlib import Path
from typing import Any

import aiohttp
from pilot import answer_prompt, banner, press, ready, until

from stairbot.console.app import build_app
from stairbot.recording import topics
from stairbot.recording.live import start_live

PROTOCOL = "foxglove.sdk.v1"
WAIT_S = 120.0  # a hang guard only


async def _advertised(ws: aiohttp.ClientWebSocketResponse, want: set[str]) -> dict[str, Any]:
    channels: dict[str, Any] = {}
    while want - set(channels):
        msg = await ws.receive(timeout=WAIT_S)
        data = json.loads(msg.data)
        if data["op"] == "advertise":
            channels.update({c["topic"]: c for c in data["channels"]})
    return channels


async def _messages(ws: aiohttp.ClientWebSocketResponse, sub: int, n: int) -> list[bytes]:
    """The next ``n`` messages of subscription ``sub`` (others passed over)."""
    out: list[bytes] = []
    while len(out) < n:
        msg = await ws.receive(timeout=WAIT_S)
        if msg.type is aiohttp.WSMsgType.BINARY:
            _op, got, _t = struct.unpack_from("<BIQ", msg.data)
            if got == sub:
                out.append(msg.data[13:])
    return out


def test_the_console_streams_its_runs_and_a_record_shares_the_channels(tmp_path: Path) -> None:
    record = tmp_path / "console.mcap"
    times: list[float] = []

    async def go() -> None:
        app = build_app(speed="1x")
        live = start_live("127.0.0.1:0", app.engine.config, "sim://")
        app.engine.live = live
        try:
            async with app.run_test(size=(80, 24)) as pilot:
                await ready(pilot)
                async with aiohttp.ClientSession() as session, session.ws_connect(
                        live.url, protocols=[PROTOCOL]) as ws:
                    channels = await _advertised(ws, {topics.SCENE, topics.MOTORS,
                                                      "/sim/true_pose"})
                    await ws.send_str(json.dumps({"op": "subscribe", "subscriptions": [
                        {"id": 1, "channelId": channels[topics.SCENE]["id"]},
                        {"id": 2, "channelId": channels[topics.MOTORS]["id"]}]}))
                    # idle, no run: the scene of the robot the console opened
                    assert len(await _messages(ws, 1, 1)) == 1
                    await press(pilot, "k")  # calibration only, at 1x
                    times.extend(json.loads(m)["time_s"] for m in await _messages(ws, 2, 5))
                    await answer_prompt(pilot, "w", str(record))
                    await until(pilot, lambda: "REC" in banner(app), "recording")
                    assert app.engine.recorder is not None
                    assert getattr(app.engine.recorder, "channels", None) is live.channels
                    times.extend(json.loads(m)["time_s"] for m in await _messages(ws, 2, 25))
                    await press(pilot, "x")
        finally:
            live.stop()
    asyncio.run(go())
    tick = build_app().engine.config.algorithm.tick
    steps = [round((b - a) / tick) for a, b in zip(times, times[1:], strict=False)]
    assert steps == [1] * len(steps)  # every tick once, in order, across the record's start
