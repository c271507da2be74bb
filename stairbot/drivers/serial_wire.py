"""The serial wire format: COBS frames delimited by 0x00, with a CRC-16.

One frame, before stuffing::

    addr  u8    board address (bits 0-3); bit 4 always set (FRAMING_3: this
                header has a length byte); bit 7 set in frames from a board
    sess  u8    the host's session: a number the host draws when it opens the
                link; a reply repeats its request's
    seq   u8    the host's sequence number; a reply repeats its request's
    len   u8    the number of message bytes that follow, up to the CRC
    then one or more messages, each:
      type  u8    message type (messages.py)
      len   u8    payload length (0..8), so an unknown type can be skipped
      payload
    crc   u16   CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection,
                no final xor; check("123456789") = 0x29B1) over addr..payload,
                big-endian

The length byte closes a blind spot of a CRC without a final xor: the CRC
of a body followed by its own CRC is 0, so without ``len`` a frame whose
CRC ends in 0x00, with the bytes ``01 01`` inserted before its delimiter,
decodes (body + 00 00) as the same frame plus one zero-length message.  With
it, any byte added or lost after the header contradicts ``len``, which the
CRC covers.  The session byte tells one host's requests from another's (or from
the same host's before a restart) that reuse a sequence number: a board's
duplicate filter compares it too, and a host takes only replies of its own
session.  Bit 4 of the address makes a 2.x board drop 3.x frames as
malformed (reserved bits set) instead of misreading them, and lets a 3.x
host name a 2.x board's frames for what they are (OldFramingError).

The frame is COBS-stuffed (the ``cobs`` package) so that it holds no 0x00,
and a 0x00 follows it.  A receiver that joins mid-stream, or sees garbage,
resynchronises at the next 0x00.  The CRC is computed with the standard
library's ``binascii.crc_hqx`` (C speed; ``crc_hqx(data, 0xFFFF)`` is exactly
CRC-16/CCITT-FALSE -- the tests check it against the ``crc`` package).
"""

from __future__ import annotations

import binascii
from dataclasses import dataclass

from cobs import cobs

from stairbot.drivers.messages import (
    MAX_PAYLOAD,
    MESSAGES,
    CodecError,
    Message,
    RawMessage,
    decode,
    encode,
)

FROM_BOARD = 0x80
FRAMING_3 = 0x10  # always set: the header has a length byte (protocol 3.0)
MAX_FRAME = 254  # stuffed bytes between delimiters; longer runs are dropped as garbage
HEADER = 4  # addr, session, seq, len
MAX_MESSAGE_BYTES = MAX_FRAME - 1 - HEADER - 2
"""What fits in MAX_FRAME stuffed bytes: COBS adds one byte to a body under 254,
and the header and CRC take the rest (247)."""
MIN_BODY = HEADER + 2  # and the crc


class OldFramingError(CodecError):
    """A frame with a good CRC but no length byte: a board of protocol 2.x or
    older (its address byte lacks FRAMING_3)."""


class CrcError(CodecError):
    """A frame whose CRC does not match."""


@dataclass(frozen=True, slots=True)
class Frame:
    """One frame: who it is for or from, its sequence number, its messages,
    and the host session it belongs to."""

    board: int
    seq: int
    messages: tuple[Message | RawMessage, ...]
    from_board: bool = False
    session: int = 0


def crc16(data: bytes) -> int:
    """CRC-16/CCITT-FALSE of ``data``."""
    return binascii.crc_hqx(data, 0xFFFF)


def frame_body(frame: Frame) -> bytes:
    """The unstuffed bytes of a frame, CRC included."""
    if not 0 <= frame.board <= 0x0F or not 0 <= frame.seq <= 0xFF \
            or not 0 <= frame.session <= 0xFF:
        raise CodecError(f"board {frame.board}, session {frame.session} or seq {frame.seq} "
                         "out of range")
    if not frame.messages:
        raise CodecError("a frame needs at least one message")
    out = bytearray((frame.board | FRAMING_3 | (FROM_BOARD if frame.from_board else 0),
                     frame.session, frame.seq, 0))
    for msg in frame.messages:
        if isinstance(msg, RawMessage):
            code, payload = msg.type_code, msg.payload
        else:
            code, payload = encode(msg)
        if len(payload) > MAX_PAYLOAD:
            raise CodecError(f"payload of {len(payload)} bytes, at most {MAX_PAYLOAD}")
        out += bytes((code, len(payload)))
        out += payload
    if len(out) - HEADER > MAX_MESSAGE_BYTES:
        raise CodecError(f"{len(out) - HEADER} message bytes, at most {MAX_MESSAGE_BYTES} in "
                         "a frame (its stuffed bytes must fit in MAX_FRAME)")
    out[HEADER - 1] = len(out) - HEADER
    out += crc16(bytes(out)).to_bytes(2, "big")
    return bytes(out)


def encode_frame(frame: Frame) -> bytes:
    """The bytes on the wire: the stuffed frame and its 0x00 delimiter."""
    return cobs.encode(frame_body(frame)) + b"\x00"


def parse_body(body: bytes) -> Frame:
    """A frame from its unstuffed bytes.  Raises CrcError for a bad CRC,
    OldFramingError for a frame of protocol 2.x framing and CodecError for
    anything else malformed (the only exceptions it raises)."""
    if len(body) < MIN_BODY:
        if len(body) >= 4 and not body[0] & FRAMING_3 \
                and crc16(body[:-2]) == int.from_bytes(body[-2:], "big"):
            raise OldFramingError("a frame without a length byte (protocol 2.x framing)")
        raise CodecError(f"frame of {len(body)} bytes, at least {MIN_BODY}")
    if crc16(body[:-2]) != int.from_bytes(body[-2:], "big"):
        raise CrcError("CRC mismatch")
    addr, session, seq, length = body[0], body[1], body[2], body[3]
    if not addr & FRAMING_3:
        raise OldFramingError(f"address byte 0x{addr:02X} lacks bit 4: a frame without a "
                              "length byte (protocol 2.x framing)")
    if addr & 0x60:
        raise CodecError(f"address byte 0x{addr:02X} has reserved bits set")
    if length != len(body) - MIN_BODY:
        raise CodecError(f"length byte says {length} message bytes; the frame holds "
                         f"{len(body) - MIN_BODY}")
    msgs: list[Message | RawMessage] = []
    i, end = HEADER, len(body) - 2
    while i < end:
        if i + 2 > end:
            raise CodecError("truncated message header")
        code, n = body[i], body[i + 1]
        if n > MAX_PAYLOAD or i + 2 + n > end:
            raise CodecError(f"message 0x{code:02X}: bad length {n}")
        payload = body[i + 2:i + 2 + n]
        msgs.append(decode(code, payload) if code in MESSAGES else RawMessage(code, payload))
        i += 2 + n
    if not msgs:
        raise CodecError("a frame without a message")
    return Frame(addr & 0x0F, seq, tuple(msgs), bool(addr & FROM_BOARD), session)


def decode_frame(stuffed: bytes) -> Frame:
    """A frame from the bytes between two delimiters.  Raises CodecError."""
    try:
        body = cobs.decode(stuffed)
    except cobs.DecodeError as exc:
        raise CodecError(f"COBS: {exc}") from None
    return parse_body(body)


@dataclass
class ReaderStats:
    frames: int = 0
    crc_errors: int = 0
    malformed: int = 0  # COBS, length or payload errors
    overruns: int = 0  # runs longer than MAX_FRAME without a delimiter

    @property
    def errors(self) -> int:
        return self.crc_errors + self.malformed + self.overruns


class FrameReader:
    """Splits a byte stream into frames.  ``feed`` never raises: bad frames
    are counted in ``stats`` and dropped; the reader resynchronises at the
    next 0x00."""

    def __init__(self) -> None:
        self._buf = bytearray()
        self._skipping = False
        self.stats = ReaderStats()
        self.last_error: str | None = None

    def feed(self, data: bytes) -> list[Frame]:
        """The complete, valid frames in the stream so far."""
        self._buf += data
        frames: list[Frame] = []
        while True:
            end = self._buf.find(0)
            if end < 0:
                if len(self._buf) > MAX_FRAME:
                    if not self._skipping:
                        self.stats.overruns += 1
                    self._skipping = True
                    self._buf.clear()
                return frames
            chunk = bytes(self._buf[:end])
            del self._buf[:end + 1]
            if self._skipping:
                self._skipping = False  # the tail of an overrun: resync here
                continue
            if not chunk:
                continue  # back-to-back delimiters are allowed (a sender may flush with 0x00)
            try:
                frames.append(decode_frame(chunk))
                self.stats.frames += 1
            except CrcError as exc:
                self.stats.crc_errors += 1
                self.last_error = str(exc)
            except CodecError as exc:
                self.stats.malformed += 1
                self.last_error = str(exc)
        return frames
