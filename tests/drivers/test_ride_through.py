"""Riding through noise in real time: the retry budget fits in the watchdog
(URLs that break it are refused), a retry round feeds every board (the one
asked again too), and the
host's waits scale with time-scaled boards."""

from __future__ import annotations

import itertools
from collections.abc import Callable

import can
import pytest
from test_serial_link import ScriptedChannel, answer

from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.drivers.can_link import CanLink
from stairbot.drivers.can_robot import OPTION_DEFAULTS as CAN_DEFAULTS
from stairbot.drivers.can_wire import BROADCAST, wire
from stairbot.drivers.serial_link import SerialLink
from stairbot.drivers.serial_robot import DEFAULTS as SERIAL_DEFAULTS
from stairbot.drivers.serial_wire import Frame
from stairbot.drivers.timing import check_ride_through, link_timing
from stairbot.errors import LinkLostError, RobotUrlError
from stairbot.run.robots import RobotOptions, open_robot

_names = itertools.count()
MOTOR, SENSOR = int(m.Board.MOTOR), int(m.Board.SENSOR)


# -- the arithmetic ------------------------------------------------------------
def test_the_default_options_of_both_wires_fit_the_watchdog() -> None:
    # 3 attempts of 50 ms = 150 ms, below 250 ms - one 20 ms tick = 230 ms.
    for defaults in (SERIAL_DEFAULTS, CAN_DEFAULTS):
        assert (defaults["retries"] + 1) * defaults["timeout"] < 0.230
        check_ride_through("x://", dict(defaults), 0.02)


@pytest.mark.parametrize("url, shown", [
    ("can://virtual/{name}?timeout=0.1", "3 x 100 ms = 300 ms must be below watchdog - one tick "
                                         "= 250 - 20 ms = 230 ms"),
    ("can://virtual/{name}?timeout=0.05&retries=4", "5 x 50 ms = 250 ms"),
    ("serial://loop://?watchdog=150", "3 x 50 ms = 150 ms must be below watchdog - one tick "
                                      "= 150 - 20 ms = 130 ms"),
    ("serial://loop://?watchdog=20", "20 ms leaves nothing for retries"),
])
def test_options_that_let_a_watchdog_trip_during_retries_are_refused_in_one_line(
        url: str, shown: str) -> None:
    with pytest.raises(RobotUrlError) as err:
        open_robot(url.format(name=f"rt-{next(_names)}"), load_config(), RobotOptions())
    text = str(err.value)
    assert shown in text and "\n" not in text
    assert "watchdog" in text and "allowed" in text


def test_lockstep_and_a_watchdog_switched_off_are_exempt() -> None:
    slow = dict(SERIAL_DEFAULTS, timeout=1.0)
    check_ride_through("x://", dict(slow, lockstep=1), 0.02)
    check_ride_through("x://", dict(slow, watchdog=0), 0.02)
    with pytest.raises(RobotUrlError):
        check_ride_through("x://", slow, 0.02)


def test_the_host_waits_scale_with_time_scaled_boards_but_not_in_lockstep() -> None:
    opts = dict(CAN_DEFAULTS, timeout=0.04, grace=0.5)
    timing = link_timing(opts, 4.0)
    assert (timing.timeout_s, timing.grace_s) == (0.01, 0.125)
    timing = link_timing(dict(opts, lockstep=1), 4.0)
    assert (timing.timeout_s, timing.grace_s) == (0.04, 0.5)


# -- a retry round feeds every board: serial ----------------------------------
def test_a_serial_retry_to_one_board_feeds_the_other_boards_watchdog() -> None:
    heard: list[tuple[float, Frame]] = []
    ch: ScriptedChannel

    def respond(frame: Frame) -> bytes | None:
        heard.append((ch.t, frame))
        if frame.board == SENSOR and isinstance(frame.messages[0], m.ReadAll):
            tries = sum(1 for _, f in heard
                        if f.board == SENSOR and isinstance(f.messages[0], m.ReadAll))
            if tries <= 3:  # the sensor board's first three ReadAlls are lost
                return None
        return answer(frame, m.Status(0, 0, 250, 0))

    ch = ScriptedChannel(respond)
    link = SerialLink(ch, timeout_s=0.05, retries=2, grace_s=1.0, now=ch.now)
    reads = [link.request(MOTOR, [m.ReadAll()], send=False), link.request(SENSOR, [m.ReadAll()])]
    link.wait(reads)
    motor = [(t, f) for t, f in heard if f.board == MOTOR]
    # the ReadAll, then one Heartbeat in each of the three rounds that went
    # to the sensor board again (two retries and a revival)
    assert [type(f.messages[0]) for _, f in motor] == [m.ReadAll] + [m.Heartbeat] * 3
    times = [t for t, _ in motor]
    assert max(b - a for a, b in itertools.pairwise(times)) <= 0.05 + 1e-9
    # each of those rounds sent the sensor board its ReadAll and a Heartbeat
    sensor = [type(f.messages[0]) for _, f in heard if f.board == SENSOR]
    assert sensor == [m.ReadAll] + [m.ReadAll, m.Heartbeat] * 3
    assert link.stats.feeds == 6 and link.stats.revived == 1


def test_a_board_whose_every_retried_read_is_lost_is_still_fed_each_round() -> None:
    # A lossy line can lose one board's request attempt after attempt; the
    # Heartbeat beside each attempt still reaches it, so its watchdog is fed
    # every timeout while the host asks again.
    reached: list[tuple[float, Frame]] = []
    lost = [0]
    ch: ScriptedChannel

    def respond(frame: Frame) -> bytes | None:
        if frame.board == MOTOR and isinstance(frame.messages[0], m.ReadAll) and lost[0] < 4:
            lost[0] += 1  # the first four ReadAlls to the motor board never arrive
            return None
        reached.append((ch.t, frame))
        return answer(frame, m.Status(0, 0, 250, 0))

    ch = ScriptedChannel(respond)
    link = SerialLink(ch, timeout_s=0.05, retries=2, grace_s=1.0, now=ch.now)
    link.wait([link.request(MOTOR, [m.ReadAll()])])
    motor = [t for t, f in reached if f.board == MOTOR]
    assert lost[0] == 4 and link.stats.revived == 1
    # heard at least once a round, the gap at most one timeout (well inside
    # the 250 ms watchdog) although five ReadAll attempts went out
    assert len(motor) >= 4 and motor[0] <= 0.05 + 1e-9
    assert max(b - a for a, b in itertools.pairwise(motor)) <= 0.05 + 1e-9


def test_a_board_that_answers_only_heartbeats_is_lost_after_the_grace_period() -> None:
    # The Heartbeats of the retry rounds get through, its ReadAll never does:
    # the board is alive but the host learns nothing from it.  The read ends
    # in LinkLostError once the grace period is over instead of asking for
    # ever.
    ch: ScriptedChannel

    def respond(frame: Frame) -> bytes | None:
        assert ch.t < 5.0, "the host is still asking a board that only answers Heartbeats"
        if isinstance(frame.messages[0], m.ReadAll):
            return None
        return answer(frame, m.Status(0, 0, 250, 0))

    ch = ScriptedChannel(respond)
    link = SerialLink(ch, timeout_s=0.05, retries=2, grace_s=0.5, now=ch.now)
    with pytest.raises(LinkLostError, match=r"no reply from the motor board for 0\.[56]"):
        link.wait([link.request(MOTOR, [m.ReadAll()])])
    assert 0.5 <= ch.t < 0.5 + 4 * 0.05 and link.stats.feeds > 0


# -- a retry round feeds every board: CAN --------------------------------------
class ScriptedBus:
    """A python-can bus double: every frame the host sends goes to ``respond``
    (board, message, seq); the replies it returns come back in order."""

    channel_info = "scripted"

    def __init__(self, respond: Callable[[int, m.Message, int], list[tuple[int, m.Message]]],
                 now: Callable[[], float]) -> None:
        self.respond = respond
        self.codec = wire()
        self.sent: list[tuple[float, int, m.Message]] = []
        self.queue: list[can.Message] = []
        self.now = now
        self.session = 0

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        f = self.codec.from_can(msg)
        self.session = f.session
        self.sent.append((self.now(), f.board, f.message))
        for board, reply in self.respond(f.board, f.message, f.seq):
            self.queue.append(self.codec.to_can(board, reply, f.session, f.seq))

    def recv(self, timeout: float | None = None) -> can.Message | None:
        return self.queue.pop(0) if self.queue else None

    def shutdown(self) -> None:
        pass


def read_all_reply(board: int) -> list[tuple[int, m.Message]]:
    status = m.Status(0, 0, 250, 0)
    if board == MOTOR:
        return [(board, status)] + [(board, m.MotorTelemetry(c, 1, 0, 0, 0)) for c in range(6)]
    return ([(board, status)] + [(board, m.SensorTelemetry(c, 0, 500, 1, 0)) for c in range(4)]
            + [(board, m.ImuTelemetry(a, 0, 0, 0, 0)) for a in range(2)])


def test_a_can_retry_to_one_board_feeds_the_other_boards_watchdog() -> None:
    clock = [0.0]
    sensor_tries = [0]

    def respond(board: int, msg: m.Message, seq: int) -> list[tuple[int, m.Message]]:
        if isinstance(msg, m.Heartbeat):
            return [(board, m.Status(0, 0, 250, 0))]
        out = read_all_reply(MOTOR) if board in (MOTOR, BROADCAST) else []
        if board in (SENSOR, BROADCAST):
            sensor_tries[0] += 1
            if sensor_tries[0] > 2:  # the sensor board's first two are lost
                out += read_all_reply(SENSOR)
        return out

    bus = ScriptedBus(respond, lambda: clock[0])

    def now() -> float:
        clock[0] += 0.01  # time moves on with every look at the clock
        return clock[0]

    link = CanLink(bus, timeout_s=0.05, retries=2, grace_s=1.0, now=now)  # type: ignore[arg-type]
    replies = link.wait(link.broadcast(m.ReadAll()))
    assert [r.board for r in replies] == [MOTOR, SENSOR]
    # the broadcast ReadAll, then each retry round: the ReadAll again to the
    # sensor board and a Heartbeat to the motor board
    sent = [(b, type(msg)) for _, b, msg in bus.sent]
    assert sent == [(BROADCAST, m.ReadAll)] + [
        (SENSOR, m.ReadAll), (MOTOR, m.Heartbeat), (SENSOR, m.Heartbeat)] * 2
    assert link.stats.retries == 2 and link.stats.feeds == 4
