"""A DBC frame's signals as bit fields of one integer, for the codec's hot path.

Every signal of a frame of ``stairbot.dbc`` is a plain little-endian integer
(Intel byte order, no scale applied to the raw value, no multiplexing): the
payload read as one little-endian integer holds each signal's raw value at
its start bit, ``length`` bits wide, two's complement when signed.  A
:class:`Layout` is that reading of one frame, taken from the frame as
cantools loaded it from the DBC -- the DBC stays the one source of ids and
signals -- so that a frame is packed and unpacked with a few integer
operations instead of cantools' general encoder (dictionaries of signal
values, scaling and choice checks each time).  It gives the raw values and
payloads cantools gives with ``scaling=False`` and padding bits zero
(tests/drivers/test_can_layout.py checks every frame against cantools);
:meth:`Layout.of` declines a frame it cannot read so (a big-endian or float
signal, a multiplexed or container frame), which the codec then leaves to
cantools.  A frame whose signals are whole bytes, 1, 2, 4 or 8 of them each,
in order, is also packed with one :class:`struct.Struct` (pad bytes between
and after): the same bytes, in one call.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True, slots=True)
class Field:
    """One signal: its start bit, its mask (``length`` ones) and its sign bit
    (0 when unsigned)."""

    shift: int
    mask: int
    sign: int


@dataclass(frozen=True, slots=True)
class Layout:
    """A frame of ``length`` bytes whose signals are ``fields``, in the order
    the codec gives their values (the message's fields)."""

    length: int
    fields: tuple[Field, ...]
    packer: struct.Struct | None = None  # the same layout, when struct can say it

    @classmethod
    def of(cls, frame: Any, signals: Sequence[Any]) -> Layout | None:
        """The layout of the cantools frame ``frame`` with its ``signals`` in
        this order; None when a signal is not a plain little-endian integer
        or the frame is multiplexed or a container."""
        if frame.is_multiplexed() or getattr(frame, "is_container", False):
            return None
        fields: list[Field] = []
        for sig in signals:
            if (sig.byte_order != "little_endian" or sig.is_float or sig.length < 1
                    or sig.start + sig.length > 8 * frame.length):
                return None
            mask = (1 << sig.length) - 1
            fields.append(Field(sig.start, mask, 1 << (sig.length - 1) if sig.is_signed else 0))
        return cls(frame.length, tuple(fields), _packer(frame.length, signals))

    def pack(self, values: Sequence[int]) -> bytes:
        """The payload carrying ``values`` (raw integers that fit their
        signals: the codec checks that first), unused bits zero."""
        if self.packer is not None:
            return self.packer.pack(*values)
        word = 0
        for f, value in zip(self.fields, values, strict=True):
            word |= (value & f.mask) << f.shift
        return word.to_bytes(self.length, "little")

    def unpack(self, data: bytes) -> tuple[int, ...]:
        """The raw value of each signal in ``data`` (``length`` bytes: the
        codec checks that first)."""
        if self.packer is not None:
            return self.packer.unpack(data)
        word = int.from_bytes(data, "little")
        out = []
        for f in self.fields:
            value = (word >> f.shift) & f.mask
            if value & f.sign:
                value -= f.mask + 1
            out.append(value)
        return tuple(out)


_CODES = {8: "b", 16: "h", 32: "i", 64: "q"}


def _packer(length: int, signals: Sequence[Any]) -> struct.Struct | None:
    """A little-endian Struct of ``signals`` (plain little-endian integers,
    in this order) when each is whole bytes of a struct size and each starts
    after the one before; pad bytes fill the gaps.  Else None."""
    fmt, at = "<", 0
    for sig in signals:
        code = _CODES.get(sig.length)
        if code is None or sig.start % 8 or sig.start < at:
            return None
        fmt += "x" * ((sig.start - at) // 8) + (code if sig.is_signed else code.upper())
        at = sig.start + sig.length
    fmt += "x" * ((8 * length - at) // 8)
    packer = struct.Struct(fmt)
    return packer if packer.size == length else None
