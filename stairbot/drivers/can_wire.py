"""The boards' messages on CAN: one message per classic data frame, 29-bit ids.

Every frame of the real boards, its id and its signals are in
``stairbot.dbc`` (shipped beside this module); the DBCs registered with the
codec (``messages.register``: the fakes' simulation-only frames, once
``stairbot.fakes`` is imported) add to it.  This module reads them with
cantools and maps their frames onto the transport-independent messages of
:mod:`stairbot.drivers.messages`:

* id = ``base << 18 | session << 8 | seq`` (an extended identifier, protocol
  4.0).  ``base = kind << 4 | board`` comes first, so arbitration still goes
  by it: its high 7 bits say which message (a lower kind wins, so EStop, kind
  0, beats everything whatever its session and seq), its low 4 bits which
  board -- the board a host frame is for (1 motor, 2 sensor, 15 both), or the
  board a reply comes from.  ``session`` (10 bits) is the host's, drawn when
  it opens the bus; ``seq`` (8 bits) numbers the host's frames; a board's
  reply repeats both.  The DBC holds each frame's base with session = seq =
  0; it is loaded with the frame id mask :data:`FRAME_ID_MASK`, as any tool
  decoding captured traffic must (``cantools decode -m 0x1FFC0000``).  A DBC
  frame is named ``<Message>_<Motor|Sensor|All>``.
* the payload is exactly the message's payload of docs/protocol.md (little-
  endian, at most 8 bytes), so the DLC says the message length; the signals
  of a frame are the message's fields in order.  The DBC carries the units
  (0.001 turn/s, 0.001 turn, mm...), so any CAN tool decodes captured
  traffic; this module works on the raw integers.

:func:`decode_frame` never raises anything but CodecError, whatever the id,
the flags or the bytes.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from functools import lru_cache
from importlib import resources
from typing import Any

import can
import cantools

from stairbot.drivers import messages as m
from stairbot.drivers.can_layout import Layout

DBC_NAME = "stairbot.dbc"
BROADCAST = m.BROADCAST
BOARD_SUFFIX: dict[str, int] = {"Motor": int(m.Board.MOTOR), "Sensor": int(m.Board.SENSOR),
                                "All": BROADCAST}
BASE_SHIFT = 18
SESSION_SHIFT = 8
FRAME_ID_MASK = 0x1FFC0000
"""The bits of an id that name the frame (its base); what a tool masks with."""
SESSION_MAX = (1 << (BASE_SHIFT - SESSION_SHIFT)) - 1  # 1023
SEQ_MASK = (1 << SESSION_SHIFT) - 1  # 255
BASE_MAX = 0x7FF  # 11 bits: the protocol 3.x id, whole


def make_id(base: int, session: int, seq: int) -> int:
    """The 29-bit id of the frame ``base`` in host session ``session``, number ``seq``."""
    return base << BASE_SHIFT | (session & SESSION_MAX) << SESSION_SHIFT | (seq & SEQ_MASK)


def split_id(frame_id: int) -> tuple[int, int, int]:
    """``(base, session, seq)`` of a 29-bit id."""
    return (frame_id >> BASE_SHIFT, (frame_id >> SESSION_SHIFT) & SESSION_MAX,
            frame_id & SEQ_MASK)


def frame_bits(data_bytes: int) -> int:
    """Bits a classic CAN frame with a 29-bit id and ``data_bytes`` of data
    occupies on the bus at worst: 64 frame bits + 8 per data byte, the most
    stuff bits the 54 + 8n stuffed bits can need (one per 4 after the first),
    and the 3-bit interframe space.  160 bits for 8 bytes, 80 for none (an
    11-bit id would take 135 and 55)."""
    n = 8 * data_bytes
    return 64 + n + (54 + n - 1) // 4 + 3


@dataclass(frozen=True, slots=True)
class CanFrame:
    """A decoded data frame: the board it is for (a host frame) or from (a
    board's), its message, and the host session and sequence number its id
    carries."""

    board: int
    message: m.Message
    session: int
    seq: int


class CanWire:
    """The DBC's frames, indexed both ways.  Raises ValueError at load when
    the DBC and the message model disagree (a name, a length, a field count)."""

    def __init__(self, db: Any) -> None:
        self.db = db
        by_name = {cls.__name__: cls for cls in m.MESSAGES.values()}
        # by base (the id's 11 high bits, the protocol 3.x id); each frame's
        # Layout, or None where cantools itself packs it
        self._by_id: dict[int, tuple[int, type[m.Message], Any, tuple[str, ...],
                                     Layout | None]] = {}
        self._by_key: dict[tuple[int, int], tuple[int, Any, tuple[str, ...], Layout | None]] = {}
        # per message class: (field name, signal name, lowest raw, highest raw)
        self._layout: dict[type[m.Message], tuple[tuple[str, str, int, int], ...]] = {}
        self.kinds: dict[int, int] = {}  # message type code -> kind
        for frame in db.messages:
            cls_name, _, suffix = frame.name.rpartition("_")
            cls = by_name.get(cls_name)
            board = BOARD_SUFFIX.get(suffix)
            if cls is None or board is None:
                raise ValueError(f"{DBC_NAME}: frame {frame.name} is not <Message>_<Motor|"
                                 "Sensor|All> for a message the codec knows "
                                 "(drivers/messages.py, or one registered with it)")
            base, seq_bits = frame.frame_id >> BASE_SHIFT, frame.frame_id & ~FRAME_ID_MASK
            if not frame.is_extended_frame or seq_bits or base > BASE_MAX or base & 0x0F != board:
                raise ValueError(f"{DBC_NAME}: {frame.name} has id 0x{frame.frame_id:08X}; "
                                 "expected an extended id base << 18, the base's low 4 bits "
                                 f"board {board}")
            if self.kinds.setdefault(cls.TYPE, base >> 4) != base >> 4:
                raise ValueError(f"{DBC_NAME}: {frame.name} has kind {base >> 4}, "
                                 f"other {cls_name} frames {self.kinds[cls.TYPE]}")
            if frame.length != m.payload_size(cls.TYPE):
                raise ValueError(f"{DBC_NAME}: {frame.name} is {frame.length} bytes; "
                                 f"{cls_name} is {m.payload_size(cls.TYPE)}")
            signals = sorted(frame.signals, key=lambda s: s.start)
            names = tuple(s.name for s in signals)
            n_fields = len(fields(cls))
            if len(names) != n_fields:
                raise ValueError(f"{DBC_NAME}: {frame.name} has {len(names)} signals; "
                                 f"{cls_name} has {n_fields} fields")
            layout = Layout.of(frame, signals)
            self._by_id[base] = (board, cls, frame, names, layout)
            self._layout[cls] = tuple(
                (f.name, sig.name, -(1 << (sig.length - 1)) if sig.is_signed else 0,
                 (1 << (sig.length - 1)) - 1 if sig.is_signed else (1 << sig.length) - 1)
                for f, sig in zip(fields(cls), signals, strict=True))
            self._by_key[(cls.TYPE, board)] = (base, frame, names, layout)

    def base(self, board: int, msg_type: type[m.Message]) -> int:
        """The base (``kind << 4 | board``) of ``msg_type`` for/from ``board``;
        CodecError if the DBC has no such frame (e.g. SetWheelSpeeds to the
        sensor board)."""
        entry = self._by_key.get((msg_type.TYPE, board))
        if entry is None:
            raise m.CodecError(f"no CAN frame for {msg_type.__name__} and board {board}")
        return entry[0]

    def frame_id(self, board: int, msg_type: type[m.Message], session: int = 0,
                 seq: int = 0) -> int:
        """The 29-bit id of ``msg_type`` for/from ``board`` in ``session`` with
        ``seq``; CodecError as :meth:`base`."""
        return make_id(self.base(board, msg_type), session, seq)

    def encode(self, board: int, msg: m.Message, session: int = 0,
               seq: int = 0) -> tuple[int, bytes]:
        """``(id, data)`` of ``msg`` for/from ``board``, the id carrying
        ``session`` and ``seq``.  Raises CodecError when there is no such
        frame, a field does not fit its signal, or the session or seq does
        not fit its bits."""
        entry = self._by_key.get((msg.TYPE, board))
        if entry is None:
            raise m.CodecError(f"no CAN frame for {type(msg).__name__} and board {board}")
        if not (0 <= session <= SESSION_MAX and 0 <= seq <= SEQ_MASK):
            raise m.CodecError(f"session {session} (0..{SESSION_MAX}) or seq {seq} "
                               f"(0..{SEQ_MASK}) out of range")
        base, frame, _, layout = entry
        spec = self._layout[type(msg)]
        values = []
        for name, signal, low, high in spec:
            value = getattr(msg, name)
            if not (isinstance(value, int) and low <= value <= high):
                raise m.CodecError(f"{type(msg).__name__}.{name} = {value!r} does not fit "
                                   f"signal {signal} ({low}..{high})")
            values.append(value)
        # the ranges are checked above, on the raw integers
        if layout is not None:
            return make_id(base, session, seq), layout.pack(values)
        raw = {signal: value for (_, signal, _, _), value in zip(spec, values, strict=True)}
        try:
            data = frame.encode(raw, scaling=False, strict=False)
        except (cantools.database.EncodeError, ValueError, TypeError) as exc:
            raise m.CodecError(f"{type(msg).__name__}: {exc}") from None
        return make_id(base, session, seq), bytes(data)

    def decode(self, frame_id: int, data: bytes) -> CanFrame:
        """The frame with the 29-bit id ``frame_id`` and ``data``.  Raises
        CodecError (only) for an id whose base the DBC does not have or data
        of the wrong length."""
        base, session, seq = split_id(frame_id)
        entry = self._by_id.get(base) if 0 <= frame_id < 1 << 29 else None
        if entry is None:
            raise m.CodecError(f"unknown CAN id 0x{frame_id:08X} (base 0x{base:03X})")
        board, cls, frame, names, layout = entry
        if len(data) != frame.length:
            raise m.CodecError(f"{frame.name}: {len(data)} data bytes, expected {frame.length}")
        try:
            if layout is not None:
                return CanFrame(board, cls(*layout.unpack(bytes(data))), session, seq)
            values = frame.decode(bytes(data), decode_choices=False, scaling=False)
            return CanFrame(board, cls(*(int(values[n]) for n in names)), session, seq)
        except Exception as exc:  # cantools' own errors; nothing may escape
            raise m.CodecError(f"{frame.name}: {exc}") from None

    def to_can(self, board: int, msg: m.Message, session: int = 0,
               seq: int = 0) -> can.Message:
        """A python-can classic data frame, extended id, carrying ``msg``."""
        fid, data = self.encode(board, msg, session, seq)
        return can.Message(arbitration_id=fid, data=data, is_extended_id=True,
                           is_fd=False, check=False)

    def from_can(self, frame: can.Message) -> CanFrame:
        """A received python-can frame, decoded.  CodecError for error frames,
        remote frames, 11-bit ids (protocol 3.x and older), CAN FD and unknown
        data."""
        if frame.is_error_frame:
            raise m.CodecError("CAN error frame")
        if frame.is_remote_frame or not frame.is_extended_id or frame.is_fd:
            raise m.CodecError(f"not a classic extended data frame (id 0x{frame.arbitration_id:X}"
                               f", remote={frame.is_remote_frame}, "
                               f"extended={frame.is_extended_id}, fd={frame.is_fd})")
        return self.decode(frame.arbitration_id, bytes(frame.data))

    # -- protocol 3.x: only Identify and Ident, to tell an old board ----------------
    def old_identify(self, board: int) -> can.Message:
        """Identify to ``board`` as protocol 3.x sent it: an 11-bit id (the
        base alone).  A 3.x board answers it with an 11-bit Ident, whose
        layout every version keeps; a 4.x board ignores it."""
        return can.Message(arbitration_id=self.base(board, m.Identify), data=b"",
                           is_extended_id=False, check=False)

    def old_ident(self, frame: can.Message) -> tuple[int, m.Ident] | None:
        """``(board, Ident)`` when ``frame`` is a protocol 3.x board's Ident
        (an 11-bit id, 8 bytes); None for any other frame."""
        if frame.is_extended_id or frame.is_error_frame or frame.is_remote_frame or frame.is_fd:
            return None
        entry = self._by_id.get(frame.arbitration_id)
        if entry is None or entry[1] is not m.Ident or len(frame.data) != 8:
            return None
        try:
            ident = m.decode(m.Ident.TYPE, bytes(frame.data))
        except m.CodecError:
            return None
        return (entry[0], ident) if isinstance(ident, m.Ident) else None

    def describe(self, frame_id: int, data: bytes) -> str:
        """The frame as the DBC reads it, physical units and names, for logs."""
        try:
            frame = self.db.get_message_by_frame_id(frame_id)
            _, session, seq = split_id(frame_id)
            return f"{frame.name} session {session} seq {seq} {frame.decode(bytes(data))}"
        except Exception as exc:  # a log line must never fail
            return f"0x{frame_id:08X} {bytes(data).hex()} (undecodable: {exc})"


def load_dbc(path: str | None = None) -> Any:
    """The shipped DBC (or the one at ``path``), loaded by cantools with the
    frame id mask :data:`FRAME_ID_MASK`, so that it finds a frame by the id
    on the wire, whatever its session and seq."""
    if path is None:
        text = resources.files("stairbot.drivers").joinpath(DBC_NAME).read_text()
        return cantools.database.load_string(text, database_format="dbc", strict=True,
                                             frame_id_mask=FRAME_ID_MASK)
    return cantools.database.load_file(path, database_format="dbc", strict=True,
                                       frame_id_mask=FRAME_ID_MASK)


def wire() -> CanWire:
    """The shared CanWire of the shipped DBC and the DBCs registered with
    the codec so far (``messages.registered_dbcs``): loaded once per set."""
    return _wire(m.registered_dbcs())


@lru_cache(maxsize=4)
def _wire(extra: tuple[str, ...]) -> CanWire:
    db = load_dbc()
    for text in extra:
        db.add_dbc_string(text)
    return CanWire(db)
