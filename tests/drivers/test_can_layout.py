"""The codec's bit-field layouts give what cantools gives: every frame of the
shipped and the simulation's DBC packed and unpacked both ways, at random and
at every signal's extremes, by its Struct where it has one and by its bit
fields; frames a layout cannot read are left to cantools."""

from __future__ import annotations

import dataclasses
import random
from typing import Any

import cantools
import pytest

import stairbot.fakes  # noqa: F401  (registers the simulation's frames)
from stairbot.drivers.can_layout import Layout
from stairbot.drivers.can_wire import wire


def _frames() -> list[Any]:
    return list(wire().db.messages)


def _extremes(sig: Any) -> tuple[int, int]:
    if sig.is_signed:
        return -(1 << (sig.length - 1)), (1 << (sig.length - 1)) - 1
    return 0, (1 << sig.length) - 1


@pytest.mark.parametrize("frame", _frames(), ids=lambda f: f.name)
def test_every_frame_packs_and_unpacks_as_cantools_does(frame: Any) -> None:
    signals = sorted(frame.signals, key=lambda s: s.start)
    found = Layout.of(frame, signals)
    assert found is not None, "every shipped frame is plain little-endian integers"
    for layout in (found, dataclasses.replace(found, packer=None)):
        _agrees(frame, signals, layout)


def _packer(name: str) -> object:
    frame = next(f for f in _frames() if f.name == name)
    layout = Layout.of(frame, sorted(frame.signals, key=lambda s: s.start))
    assert layout is not None
    return layout.packer


def test_most_frames_have_a_struct_and_nibbles_do_not() -> None:
    assert _packer("MotorTelemetry_Motor") is None  # channel and mode share a byte
    assert _packer("SensorTelemetry_Sensor") is not None
    assert _packer("EStop_All") is not None


def _agrees(frame: Any, signals: list[Any], layout: Layout) -> None:
    rng = random.Random(frame.frame_id)
    cases = [[_extremes(s)[0] for s in signals], [_extremes(s)[1] for s in signals],
             [0 for _ in signals]]
    cases += [[rng.randint(*_extremes(s)) for s in signals] for _ in range(200)]
    for values in cases:
        expected = frame.encode({s.name: v for s, v in zip(signals, values, strict=True)},
                                scaling=False, strict=False)
        assert layout.pack(values) == bytes(expected)
        assert layout.unpack(bytes(expected)) == tuple(values)
    for _ in range(200):  # any payload, padding bits set too
        data = bytes(rng.getrandbits(8) for _ in range(frame.length))
        decoded = frame.decode(data, decode_choices=False, scaling=False)
        assert layout.unpack(data) == tuple(int(decoded[s.name]) for s in signals)


DBC = """VERSION ""
BU_: B
BO_ 2147745792 Odd_Motor: 4 B
 SG_ Big : 7|16@0- (1,0) [0|0] "" B
 SG_ Low : 16|8@1+ (1,0) [0|0] "" B
BO_ 2147745808 Float_Motor: 4 B
 SG_ Value : 0|32@1- (1,0) [0|0] "" B
SIG_VALTYPE_ 2147745808 Value : 1;
"""


def test_a_big_endian_or_float_signal_is_left_to_cantools() -> None:
    db = cantools.database.load_string(DBC, database_format="dbc", strict=True)
    for frame in db.messages:
        assert Layout.of(frame, sorted(frame.signals, key=lambda s: s.start)) is None
