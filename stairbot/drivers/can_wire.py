"""The boards' messages on CAN: one message per classic data frame, 11-bit ids.

Every frame, its id and its signals are in ``stairbot.dbc`` (shipped beside
this module); this module reads the DBC with cantools and maps its frames onto
the transport-independent messages of :mod:`stairbot.drivers.messages`:

* id = ``kind << 4 | board``: the high 7 bits say which message (a lower kind
  wins arbitration, so EStop, kind 0, beats everything), the low 4 bits which
  board -- the board a host frame is for (1 motor, 2 sensor, 15 both), or the
  board a reply comes from.  A DBC frame is named ``<Message>_<Motor|Sensor|All>``.
* the payload is exactly the message's payload of docs/protocol.md (little-
  endian, at most 8 bytes), so the DLC says the message length; the signals
  of a frame are the message's fields in order.  The DBC carries the units
  (0.001 turn/s, 0.001 turn, mm...), so any CAN tool decodes captured
  traffic; this module works on the raw integers.

:func:`decode_frame` never raises anything but CodecError, whatever the id,
the flags or the bytes.
"""

from __future__ import annotations

from dataclasses import fields
from functools import lru_cache
from importlib import resources
from typing import Any

import can
import cantools

from stairbot.drivers import messages as m

DBC_NAME = "stairbot.dbc"
BROADCAST = m.BROADCAST
BOARD_SUFFIX: dict[str, int] = {"Motor": int(m.Board.MOTOR), "Sensor": int(m.Board.SENSOR),
                                "All": BROADCAST}
STANDARD_ID_MAX = 0x7FF


def frame_bits(data_bytes: int) -> int:
    """Bits a classic CAN frame with an 11-bit id and ``data_bytes`` of data
    occupies on the bus at worst: 44 frame bits + 8 per data byte, the most
    stuff bits the 34 + 8n stuffed bits can need (one per 4 after the first),
    and the 3-bit interframe space.  135 bits for 8 bytes, 55 for none."""
    n = 8 * data_bytes
    return 44 + n + (34 + n - 1) // 4 + 3


class CanWire:
    """The DBC's frames, indexed both ways.  Raises ValueError at load when
    the DBC and the message model disagree (a name, a length, a field count)."""

    def __init__(self, db: Any) -> None:
        self.db = db
        by_name = {cls.__name__: cls for cls in m.MESSAGES.values()}
        self._by_id: dict[int, tuple[int, type[m.Message], Any, tuple[str, ...]]] = {}
        self._by_key: dict[tuple[int, int], tuple[int, Any, tuple[str, ...]]] = {}
        # per message class: (field name, signal name, lowest raw, highest raw)
        self._layout: dict[type[m.Message], tuple[tuple[str, str, int, int], ...]] = {}
        self.kinds: dict[int, int] = {}  # message type code -> kind
        for frame in db.messages:
            cls_name, _, suffix = frame.name.rpartition("_")
            cls = by_name.get(cls_name)
            board = BOARD_SUFFIX.get(suffix)
            if cls is None or board is None:
                raise ValueError(f"{DBC_NAME}: frame {frame.name} is not <Message>_<Motor|"
                                 "Sensor|All> for a message of drivers/messages.py")
            fid = frame.frame_id
            if frame.is_extended_frame or fid > STANDARD_ID_MAX or fid & 0x0F != board:
                raise ValueError(f"{DBC_NAME}: {frame.name} has id 0x{fid:03X}; "
                                 f"expected an 11-bit id ending in board {board}")
            if self.kinds.setdefault(cls.TYPE, fid >> 4) != fid >> 4:
                raise ValueError(f"{DBC_NAME}: {frame.name} has kind {fid >> 4}, "
                                 f"other {cls_name} frames {self.kinds[cls.TYPE]}")
            if frame.length != m.payload_size(cls.TYPE):
                raise ValueError(f"{DBC_NAME}: {frame.name} is {frame.length} bytes; "
                                 f"{cls_name} is {m.payload_size(cls.TYPE)}")
            names = tuple(s.name for s in sorted(frame.signals, key=lambda s: s.start))
            n_fields = len(fields(cls))
            if len(names) != n_fields:
                raise ValueError(f"{DBC_NAME}: {frame.name} has {len(names)} signals; "
                                 f"{cls_name} has {n_fields} fields")
            self._by_id[fid] = (board, cls, frame, names)
            self._layout[cls] = tuple(
                (f.name, sig.name, -(1 << (sig.length - 1)) if sig.is_signed else 0,
                 (1 << (sig.length - 1)) - 1 if sig.is_signed else (1 << sig.length) - 1)
                for f, sig in zip(fields(cls), sorted(frame.signals, key=lambda s: s.start),
                                  strict=True))
            self._by_key[(cls.TYPE, board)] = (fid, frame, names)

    def frame_id(self, board: int, msg_type: type[m.Message]) -> int:
        """The id of ``msg_type`` for/from ``board``; CodecError if the DBC has
        no such frame (e.g. SetWheelSpeeds to the sensor board)."""
        entry = self._by_key.get((msg_type.TYPE, board))
        if entry is None:
            raise m.CodecError(f"no CAN frame for {msg_type.__name__} and board {board}")
        return entry[0]

    def encode(self, board: int, msg: m.Message) -> tuple[int, bytes]:
        """``(id, data)`` of ``msg`` for/from ``board``.  Raises CodecError when
        there is no such frame or a field does not fit its signal."""
        entry = self._by_key.get((msg.TYPE, board))
        if entry is None:
            raise m.CodecError(f"no CAN frame for {type(msg).__name__} and board {board}")
        fid, frame, _ = entry
        raw: dict[str, int] = {}
        for name, signal, low, high in self._layout[type(msg)]:
            value = getattr(msg, name)
            if not (isinstance(value, int) and low <= value <= high):
                raise m.CodecError(f"{type(msg).__name__}.{name} = {value!r} does not fit "
                                   f"signal {signal} ({low}..{high})")
            raw[signal] = value
        try:
            # the ranges are checked above, on the raw integers
            data = frame.encode(raw, scaling=False, strict=False)
        except (cantools.database.EncodeError, ValueError, TypeError) as exc:
            raise m.CodecError(f"{type(msg).__name__}: {exc}") from None
        return fid, bytes(data)

    def decode(self, frame_id: int, data: bytes) -> tuple[int, m.Message]:
        """``(board, message)`` of a data frame.  Raises CodecError (only) for
        an id the DBC does not have or data of the wrong length."""
        entry = self._by_id.get(frame_id)
        if entry is None:
            raise m.CodecError(f"unknown CAN id 0x{frame_id:03X}")
        board, cls, frame, names = entry
        if len(data) != frame.length:
            raise m.CodecError(f"{frame.name}: {len(data)} data bytes, expected {frame.length}")
        try:
            values = frame.decode(bytes(data), decode_choices=False, scaling=False)
            return board, cls(*(int(values[n]) for n in names))
        except Exception as exc:  # cantools' own errors; nothing may escape
            raise m.CodecError(f"{frame.name}: {exc}") from None

    def to_can(self, board: int, msg: m.Message) -> can.Message:
        """A python-can classic data frame carrying ``msg``."""
        fid, data = self.encode(board, msg)
        return can.Message(arbitration_id=fid, data=data, is_extended_id=False,
                           is_fd=False, check=False)

    def from_can(self, frame: can.Message) -> tuple[int, m.Message]:
        """``(board, message)`` of a received python-can frame.  CodecError for
        error frames, remote frames, extended ids, CAN FD and unknown data."""
        if frame.is_error_frame:
            raise m.CodecError("CAN error frame")
        if frame.is_remote_frame or frame.is_extended_id or frame.is_fd:
            raise m.CodecError(f"not a classic standard data frame (id 0x{frame.arbitration_id:X}"
                               f", remote={frame.is_remote_frame}, "
                               f"extended={frame.is_extended_id}, fd={frame.is_fd})")
        return self.decode(frame.arbitration_id, bytes(frame.data))

    def describe(self, frame_id: int, data: bytes) -> str:
        """The frame as the DBC reads it, physical units and names, for logs."""
        try:
            frame = self.db.get_message_by_frame_id(frame_id)
            return f"{frame.name} {frame.decode(bytes(data))}"
        except Exception as exc:  # a log line must never fail
            return f"0x{frame_id:03X} {bytes(data).hex()} (undecodable: {exc})"


def load_dbc(path: str | None = None) -> Any:
    """The shipped DBC (or the one at ``path``), loaded by cantools."""
    if path is None:
        text = resources.files("stairbot.drivers").joinpath(DBC_NAME).read_text()
        return cantools.database.load_string(text, database_format="dbc", strict=True)
    return cantools.database.load_file(path, database_format="dbc", strict=True)


@lru_cache(maxsize=1)
def wire() -> CanWire:
    """The shared CanWire of the shipped DBC (loaded once per process)."""
    return CanWire(load_dbc())
