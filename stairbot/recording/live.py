"""``--foxglove [HOST:]PORT`` (``stairbot run``, ``stairbot console``): the
robot live in Foxglove, served by foxglove-sdk's own WebSocket server on
the run's channels (:class:`~stairbot.recording.channels.RunChannels`):
the topics and schemas of the MCAP record, and with ``--record FILE.mcap``
the very same channels and messages, the record one sink of them and the
server another.

The server listens on 127.0.0.1 unless HOST says otherwise (another host
gets a warning: whoever reaches it sees the robot; the server takes no
commands -- no capabilities, no client channels).  PORT 0 takes any free
port; the URL printed says which.  A viewer that subscribes to ``/scene``
gets the last scene at once (it was logged when the robot was opened).
The pose channel of the robot the run opens is open before the server
starts (:meth:`~stairbot.recording.channels.RunChannels.open_pose`): a
console that opens another kind of robot later (``sim://`` to boards)
advertises the other pose topic then, and a viewer connected at that moment
may have to reconnect to get it.
The server stops with the run or the console (:meth:`LiveServer.stop`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from urllib.parse import quote

import foxglove
from foxglove.websocket import ChannelView, Client, ServerListener

from stairbot import listen
from stairbot.events import Event
from stairbot.hardware import Snapshot, Speeds
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario
from stairbot.recording import topics
from stairbot.recording.channels import RunChannels
from stairbot.recording.mcap_sink import McapRecord
from stairbot.recording.pose import PoseSource, pose_kind

OPTION = "--foxglove"
DEFAULT_PORT = 8765
"""Foxglove's own default for a WebSocket connection (``--foxglove`` alone)."""
LAYOUT = "docs/foxglove-layout.json"
APP = "https://app.foxglove.dev/"


class _Listener(ServerListener):
    """The server's callbacks: a viewer subscribing to the scene gets it."""

    def __init__(self, channels: RunChannels) -> None:
        self._channels = channels

    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        if channel.topic == topics.SCENE:
            self._channels.scene_again()


class LiveServer:
    """foxglove-sdk's WebSocket server on ``channels``, listening on (host,
    port).  Raises InputError (naming ``--foxglove``) when it cannot listen
    there.  :meth:`watch`, :meth:`write` and :meth:`tick` log on the
    channels: call them only while no MCAP record on the same channels does
    (:meth:`feed`)."""

    def __init__(self, channels: RunChannels, host: str, port: int) -> None:
        listen.check_listen(host, port, OPTION)
        self.channels = channels
        self.host = host
        channels.serve_live()
        try:
            self._server: foxglove.WebSocketServer | None = foxglove.start_server(
                name="stairbot", host=host, port=port, context=channels.context,
                channel_filter=channels.for_live, server_listener=_Listener(channels))
        except RuntimeError as exc:  # the port taken since the check, or another refusal
            raise listen.bad(OPTION, listen.shown(host, port), f"cannot listen: {exc}") from None
        self.port = self._server.port

    @property
    def url(self) -> str:
        """The ws:// URL a viewer on this machine connects to."""
        host = self.host
        if listen.is_unspecified(host):  # every interface: this machine's loopback among them
            host = "::1" if ":" in host else "127.0.0.1"
        return f"ws://{listen.shown(host, self.port)}"

    def lines(self) -> list[str]:
        """What the operator is told when the server starts: the URL, how to
        open it in Foxglove, and a warning when others can connect."""
        out = [f"Foxglove live at {self.url} (stops when the run or the console ends)",
               f"  in Foxglove: Open connection > Foxglove WebSocket > {self.url}, or "
               f"{APP}?ds=foxglove-websocket&ds.url={quote(self.url, safe='')}",
               f"  layout: import {LAYOUT} (python -m stairbot.recording.layout > "
               "stairbot-layout.json writes it)"]
        if not listen.is_loopback(self.host):
            where = "every interface" if listen.is_unspecified(self.host) else self.host
            out.append(f"warning: {OPTION} listens on {where}: any machine that reaches it "
                       "sees the robot live (the stream takes no commands)")
        return out

    # -- what a run calls (when no MCAP record logs on these channels) -----------------
    def watch(self, pose: PoseSource, scenario: Scenario, robot: str) -> None:
        """Ticks from now on come from ``robot`` on ``scenario``: the scene."""
        self.channels.watch(pose, scenario)

    def write(self, event: Event) -> None:
        self.channels.write(event)

    def tick(self, snap: Snapshot, sent: Speeds | None) -> None:
        self.channels.tick(snap, sent)

    def feed(self, record: object) -> LiveServer | None:
        """This server when the run must log to it itself; None when
        ``record`` is an MCAP record on its channels (which logs every
        message to both)."""
        if isinstance(record, McapRecord) and record.channels is self.channels:
            return None
        return self

    def stop(self) -> None:
        """Stop the server (every viewer disconnected); again: nothing."""
        server, self._server = self._server, None
        if server is not None:
            server.stop()


def start_live(text: str, config: RobotConfig, url: str) -> LiveServer:
    """The live server ``--foxglove text`` asks for, on channels of its own,
    with the pose channel of the robot at ``url`` open from the start (see
    :meth:`RunChannels.open_pose`).  Raises InputError for a bad
    ``[HOST:]PORT`` or one it cannot listen on."""
    host, port = listen.parse_bind(text, OPTION, any_port=True)
    channels = RunChannels(config)
    kind = pose_kind(url)
    channels.open_pose(kind.topic, kind.description)
    return LiveServer(channels, host, port)


@contextmanager
def serving(text: str, config: RobotConfig, url: str,
            say: Callable[[str], None]) -> Iterator[LiveServer]:
    """The live server ``--foxglove text`` asks for (a robot at ``url``),
    each of its :meth:`LiveServer.lines` given to ``say``, stopped on the way
    out.  Raises InputError (nothing started) for a bad or taken address."""
    live = start_live(text, config, url)
    try:
        for line in live.lines():
            say(line)
        yield live
    finally:
        live.stop()
