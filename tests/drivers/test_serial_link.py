"""The request/response engine on a scripted in-memory channel and a fake
clock: timeouts, retries of idempotent requests only, late and stray replies,
lost links."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from stairbot.drivers import messages as m
from stairbot.drivers.serial_link import SerialLink
from stairbot.drivers.serial_wire import Frame, FrameReader, encode_frame
from stairbot.errors import LinkLostError

Responder = Callable[[Frame], bytes | None]


class ScriptedChannel:
    """Frames the host writes go to ``respond``; its bytes come back after
    ``delay`` seconds of the fake clock."""

    def __init__(self, respond: Responder, delay: float = 0.001) -> None:
        self.respond = respond
        self.delay = delay
        self.t = 0.0
        self.heard: list[Frame] = []
        self._reader = FrameReader()
        self._due: list[tuple[float, bytes]] = []

    def now(self) -> float:
        return self.t

    def write(self, data: bytes) -> None:
        for frame in self._reader.feed(data):
            self.heard.append(frame)
            reply = self.respond(frame)
            if reply:
                self._due.append((self.t + self.delay, reply))

    def read_some(self, timeout_s: float) -> bytes:
        ready = [d for d in self._due if d[0] <= self.t + timeout_s]
        if not ready:
            self.t += timeout_s
            return b""
        first = min(ready)
        self._due.remove(first)
        self.t = max(self.t, first[0])
        return first[1]

    def close(self) -> None:
        pass


def answer(frame: Frame, *msgs: m.Message) -> bytes:
    return encode_frame(Frame(frame.board, frame.seq, msgs, from_board=True,
                              session=frame.session))


def status_reply(frame: Frame) -> bytes:
    return answer(frame, m.Status(0, 0, 250, 0))


def make_link(respond: Responder, delay: float = 0.001, **kw: int) -> tuple[
        SerialLink, ScriptedChannel]:
    ch = ScriptedChannel(respond, delay)
    return SerialLink(ch, timeout_s=0.05, now=ch.now, **kw), ch


def test_exchange_and_rtt() -> None:
    link, ch = make_link(status_reply, delay=0.002)
    reply = link.exchange(1, [m.GetStatus()])
    assert reply.board == 1 and reply.messages == (m.Status(0, 0, 250, 0),)
    assert link.stats.frames_tx == link.stats.frames_rx == 1
    assert link.stats.rtt_median_ms() == pytest.approx(2.0)


def test_two_requests_in_flight_answered_out_of_order() -> None:
    held: list[Frame] = []

    def respond(frame: Frame) -> bytes | None:
        held.append(frame)
        if len(held) == 2:  # answer the second first, then the first
            return answer(held[1], m.Ack(0, 0)) + answer(held[0], m.Ack(1, 0))
        return None

    link, _ = make_link(respond)
    p1 = link.request(1, [m.ReadAll()], send=False)
    p2 = link.request(2, [m.ReadAll()])
    r1, r2 = link.wait([p1, p2])
    assert r1.board == 1 and r1.messages == (m.Ack(1, 0),)
    assert r2.board == 2 and r2.messages == (m.Ack(0, 0),)


def test_idempotent_query_is_retried_byte_for_byte() -> None:
    calls: list[Frame] = []

    def respond(frame: Frame) -> bytes | None:
        calls.append(frame)
        return None if len(calls) == 1 else status_reply(frame)  # the first is lost

    link, _ = make_link(respond, retries=2)
    link.exchange(1, [m.ReadAll()])
    # every board is fed a Heartbeat beside the retry
    mine = [f for f in calls if f.board == 1 and not isinstance(f.messages[0], m.Heartbeat)]
    assert len(mine) == 2 and mine[0] == mine[1]  # same seq, same messages
    assert (link.stats.retries, link.stats.timeouts, link.stats.lost) == (1, 1, 0)


def test_query_without_answer_loses_the_link_after_its_retries() -> None:
    link, ch = make_link(lambda f: None, retries=2)
    with pytest.raises(LinkLostError, match="no reply from the sensor board for 0.15 s.*3 attempt"):
        link.exchange(2, [m.GetStatus()])
    asked = [f for f in ch.heard if f.board == 2 and not isinstance(f.messages[0], m.Heartbeat)]
    assert len(asked) == 3
    assert (link.stats.retries, link.stats.lost) == (2, 1)


@pytest.mark.parametrize("msg", [m.SetLiftSpeeds(100, 0), m.Move(4, 1000, 100), m.Stop(),
                                 m.EStop(), m.Clear(), m.SetWatchdog(100)],
                         ids=lambda x: type(x).__name__)
def test_commands_are_never_retried(msg: m.Message) -> None:
    link, ch = make_link(lambda f: None, retries=5)
    with pytest.raises(LinkLostError):
        link.exchange(1, [msg])
    assert len(ch.heard) == 1 and link.stats.retries == 0


def test_a_frame_mixing_a_command_with_queries_is_not_retried() -> None:
    link, ch = make_link(lambda f: None, retries=5)
    with pytest.raises(LinkLostError):
        link.exchange(1, [m.GetStatus(), m.Run(0, 500)])
    assert len(ch.heard) == 1


def test_late_reply_is_counted_late_and_stray_reply_stray() -> None:
    link, ch = make_link(status_reply, delay=0.2, retries=0)  # slower than the 50 ms timeout
    with pytest.raises(LinkLostError):
        link.exchange(1, [m.GetStatus()])
    ch.t += 1.0
    link.poll()
    assert link.stats.late == 1
    ch._due.append((ch.t, answer(Frame(1, 200, ()), m.Ack(0, 0))))  # nobody asked for seq 200
    link.poll()
    assert link.stats.stray == 1


def test_a_request_held_back_does_not_time_out_before_it_is_written() -> None:
    link, ch = make_link(status_reply)
    held = link.request(1, [m.GetStatus()], send=False)
    ch.t += 1.0  # twenty timeouts later, still in the output buffer
    link.poll()
    assert not held.failed and link.stats.timeouts == link.stats.lost == 0
    assert link.wait([held])[0].messages == (m.Status(0, 0, 250, 0),)  # wait flushes
    assert held.sent_at == 1.0 and link.stats.retries == 0


def test_a_second_copy_of_a_reply_taken_is_counted_a_duplicate() -> None:
    link, ch = make_link(lambda f: status_reply(f) * 2)
    reply = link.exchange(1, [m.GetStatus()])
    assert isinstance(reply.messages[0], m.Status)
    link.poll()
    assert (link.stats.duplicates, link.stats.stray, link.stats.late) == (1, 0, 0)


def test_a_reply_of_another_session_is_never_taken() -> None:
    """The same board and seq, but another host's session (a reply still on the
    line from a host before this one): stray, and the request is asked again."""
    def respond(frame: Frame) -> bytes | None:
        other = Frame(frame.board, frame.seq, frame.messages, session=frame.session ^ 0xFF)
        return status_reply(other) + status_reply(frame)

    link, ch = make_link(respond)
    reply = link.exchange(1, [m.GetStatus()])
    assert isinstance(reply.messages[0], m.Status)
    assert link.stats.stray == 1 and link.other_session == 1
    assert len({f.session for f in ch.heard}) == 1 and ch.heard[0].session == link.session


def test_unanswered_commands_in_a_row_lose_the_link() -> None:
    def respond(frame: Frame) -> bytes | None:
        return status_reply(frame) if frame.messages == (m.GetStatus(),) else None

    link, ch = make_link(respond, max_lost=3)
    for _ in range(3):
        link.request(1, [m.SetLiftSpeeds(0, 0)])
        ch.t += 0.1
        link.poll()
    assert link.lost_streak == 3
    with pytest.raises(LinkLostError, match="3 commands in a row"):
        link.exchange(1, [m.GetStatus()])


def test_an_answered_command_resets_the_lost_streak() -> None:
    answer_it = [False]

    def respond(frame: Frame) -> bytes | None:
        return answer(frame, m.Ack(0x21, 0)) if answer_it[0] else None

    link, ch = make_link(respond)
    link.request(1, [m.SetLiftSpeeds(0, 0)])
    ch.t += 0.1
    link.poll()
    assert link.lost_streak == 1
    answer_it[0] = True
    link.exchange(1, [m.SetLiftSpeeds(0, 0)])
    assert link.lost_streak == 0


def test_corrupted_reply_counts_a_crc_error_and_the_retry_succeeds() -> None:
    calls = [0]

    def respond(frame: Frame) -> bytes | None:
        calls[0] += 1
        wire = bytearray(status_reply(frame))
        if calls[0] == 1:
            wire[3] ^= 0x04
        return bytes(wire)

    link, _ = make_link(respond)
    link.exchange(1, [m.GetStatus()])
    assert link.stats.crc_errors + link.stats.malformed == 1
    assert link.stats.retries == 1


def test_losses_count_in_sending_order_not_in_the_order_timeouts_notice_them() -> None:
    # every other command is lost; their timeouts all fire together, later
    sent = [0]

    def respond(frame: Frame) -> bytes | None:
        sent[0] += 1
        return None if sent[0] % 2 else answer(frame, m.Ack(0x21, 0))

    link, ch = make_link(respond, max_lost=2)
    for _ in range(8):
        link.request(1, [m.SetLiftSpeeds(0, 0)])
        ch.t += 0.001
        link.poll()
    ch.t += 0.1
    link.poll()
    assert link.stats.lost == 4
    assert link.lost_streak == 0  # the last command sent was answered
