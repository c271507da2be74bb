"""What a CAN request waits for: the replies kept per message class agree
with expected_replies, worked out here from the protocol's own words, and a
reply class registered after a first request is waited for from then on."""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import ClassVar

import pytest

import stairbot.fakes  # noqa: F401  (registers the simulation's messages)
from stairbot.drivers import messages as m
from stairbot.drivers.can_request import CanRequest, Due, Offer, replies_of


def _request(board: int, *msgs: m.Message, channels: int | None = None) -> CanRequest:
    req = CanRequest(board, tuple(msgs), True, 0.0, 1.0, channels=channels)
    req.expect()
    return req


@pytest.mark.parametrize("channels", [None, 4, 6])
def test_a_readall_waits_for_status_then_each_channel_then_each_axis(
        channels: int | None) -> None:
    sensors = channels or m.BASE_SENSOR_CHANNELS
    expected = ([(m.Status, None)] + [(m.SensorTelemetry, ch) for ch in range(sensors)]
                + [(m.ImuTelemetry, axis) for axis in range(len(m.IMU_AXES))])
    for _ in range(2):  # the first time and from what was kept
        req = _request(int(m.Board.SENSOR), m.ReadAll(), channels=channels)
        assert [(d.kind, d.key) for d in req.todo] == expected
        assert {d.part for d in req.todo} == {0}


def test_each_message_of_a_request_waits_for_its_own_answer() -> None:
    req = _request(int(m.Board.MOTOR), m.Heartbeat(), m.Identify())
    assert list(req.todo) == [Due(0, m.Heartbeat.TYPE, m.Status, None),
                              Due(1, m.Identify.TYPE, m.Ident, None)]


def test_every_message_class_waits_as_expected_replies_says() -> None:
    for cls in m.MESSAGES.values():
        if cls.REPLY or cls is m.ReadAll:  # ReadAll: the tests above
            continue
        msg = cls(*(0 for _ in fields(cls)))
        answer = m.MESSAGES.get(msg.ANSWER, m.Ack)
        telemetry = answer in (m.MotorTelemetry, m.SensorTelemetry, m.ImuTelemetry)
        for board in m.Board:  # telemetry: the first (and only) of its kind
            assert replies_of(int(board), msg) == ((answer, 0 if telemetry else None),)


@dataclass(frozen=True, slots=True)
class _Ask(m.Message):
    TYPE: ClassVar[int] = 0xE7
    FORMAT: ClassVar[str] = "<"
    IDEMPOTENT: ClassVar[bool] = True
    ANSWER: ClassVar[int] = 0xE8


@dataclass(frozen=True, slots=True)
class _Answer(m.Message):
    TYPE: ClassVar[int] = 0xE8
    FORMAT: ClassVar[str] = "<"
    REPLY: ClassVar[bool] = True


def test_an_answer_registered_after_a_first_request_is_waited_for(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(m.MESSAGES, _Ask.TYPE, _Ask)
    monkeypatch.delitem(m.MESSAGES, _Answer.TYPE, raising=False)
    before = _request(int(m.Board.MOTOR), _Ask())
    assert [d.kind for d in before.todo] == [m.Ack]  # an unknown answer: an Ack
    monkeypatch.setitem(m.MESSAGES, _Answer.TYPE, _Answer)
    after = _request(int(m.Board.MOTOR), _Ask())
    assert [d.kind for d in after.todo] == [_Answer]
    assert after.offer(_Answer(), 0) is Offer.TAKEN


def test_a_reply_after_a_lost_one_is_taken_and_leaves_a_gap() -> None:
    req = _request(int(m.Board.MOTOR), m.ReadAll(), channels=2)
    assert req.offer(m.Status(0, 0, 250, 0), 0) is Offer.TAKEN
    tel = m.MotorTelemetry(1, 0, 0, 0, 0)
    assert req.offer(tel, 0) is Offer.TAKEN  # channel 0's was lost
    assert req.gap and [d.key for d in req.skipped] == [0]
    assert req.offer(tel, 0) is Offer.DUPLICATE
