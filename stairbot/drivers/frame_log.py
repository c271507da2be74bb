"""Raw frames to a file, as the wire carried them: the ``log=FILE`` option of
``can://`` and ``serial://`` URLs.

* CAN: every frame the host sends and every frame it receives, written by
  python-can's own writers, chosen by the file's extension (``can.Logger``):
  ``.log`` candump ``-L`` (``can.CanutilsLogWriter``), ``.asc`` Vector ASC
  (``can.ASCWriter``), ``.trc`` PCAN-View, ``.csv``.  Each reads back with
  ``can.LogReader`` and replays with ``can.Player``; a ``.log`` decodes with
  ``python -m cantools decode -m 0x1FFC0000 stairbot/drivers/stairbot.dbc < FILE``
  (a lockstep run's with ``stairbot/fakes/stairbot_sim.dbc`` appended to the
  DBC: docs/protocol.md, "Decoding captured traffic").
* serial: one line per frame, ``TIME DIR HEX``: the wall time (seconds since
  the epoch, to the microsecond), ``TX`` (host to boards) or ``RX``, and the
  frame's bytes on the line, COBS-stuffed, its 0x00 delimiter included
  (``serial_wire.decode_frame`` takes them without the delimiter).

Each frame is flushed to the file as it is written: a host that dies leaves
every frame it sent or heard before.  A write that fails (a full disk) stops
the log, never the robot: the link goes on and ``failed`` says why (shown in
the robot's diagnostics).  Opening the file is checked when the robot opens:
a bad path or an extension no writer takes is a RobotUrlError, one line.
"""

from __future__ import annotations

import threading
import time
from pathlib import Path
from typing import Any, TextIO

import can

from stairbot.errors import RobotUrlError

CAN_FORMATS = {".log": "candump -L", ".asc": "Vector ASC", ".trc": "PCAN trace",
               ".csv": "python-can CSV"}
"""The extensions a CAN log may have: python-can's text writers, which
``can.LogReader`` reads back and which flush line by line."""


def check_can_log(url: str, path: str) -> None:
    """RobotUrlError unless ``path`` has an extension of :data:`CAN_FORMATS`."""
    suffix = Path(path).suffix.lower()
    if not path or suffix not in CAN_FORMATS:
        allowed = ", ".join(f"{k} ({v})" for k, v in CAN_FORMATS.items())
        raise RobotUrlError(url, "log", f"{path!r} has no frame-log extension; allowed: "
                            f"{allowed}")


def _cannot(url: str, path: str, exc: OSError) -> RobotUrlError:
    return RobotUrlError(url, "log", f"cannot write {path}: {exc.strerror or exc}")


class CanFrameLog:
    """Frames of a CAN bus to a python-can writer (see the module docstring).
    Thread-safe: the emergency stop sends from its own thread."""

    def __init__(self, url: str, path: str) -> None:
        check_can_log(url, path)
        self.path = path
        try:
            self._writer: Any = can.Logger(path)
        except OSError as exc:
            raise _cannot(url, path, exc) from None
        self._lock = threading.Lock()
        self.failed: str | None = None
        self.frames = 0

    def write(self, frame: can.Message, rx: bool) -> None:
        """Log ``frame`` (``rx``: received), stamped now unless it has a time."""
        with self._lock:
            if self.failed is not None or self._writer is None:
                return
            copy = can.Message(
                timestamp=frame.timestamp or time.time(), arbitration_id=frame.arbitration_id,
                is_extended_id=frame.is_extended_id, is_remote_frame=frame.is_remote_frame,
                is_error_frame=frame.is_error_frame, is_fd=frame.is_fd, dlc=frame.dlc,
                data=bytes(frame.data), is_rx=rx, check=False)
            try:
                self._writer.on_message_received(copy)
                self._writer.file.flush()
            except (OSError, ValueError) as exc:
                self.failed = f"{self.path}: cannot write the frame log: {exc}"
                return
            self.frames += 1

    def close(self) -> None:
        with self._lock:
            writer, self._writer = self._writer, None
        if writer is not None:
            try:
                writer.stop()
            except (OSError, ValueError) as exc:
                self.failed = self.failed or f"{self.path}: cannot close the frame log: {exc}"

    def describe(self) -> dict[str, object]:
        return {"path": self.path, "frames": self.frames, "failed": self.failed}


class SerialFrameLog:
    """Frames of a serial line, one line each (see the module docstring).
    Bytes are cut into frames at each 0x00 delimiter; a frame read in pieces
    is logged once whole.  Thread-safe."""

    def __init__(self, url: str, path: str) -> None:
        self.path = path
        try:
            self._file: TextIO | None = open(path, "w", encoding="ascii")  # noqa: SIM115
        except OSError as exc:
            raise _cannot(url, path, exc) from None
        self._lock = threading.Lock()
        self._partial = {"TX": bytearray(), "RX": bytearray()}
        self.failed: str | None = None
        self.frames = 0

    def tx(self, data: bytes) -> None:
        """Bytes the host wrote."""
        self._feed("TX", data)

    def rx(self, data: bytes) -> None:
        """Bytes the host read."""
        self._feed("RX", data)

    def _feed(self, direction: str, data: bytes) -> None:
        with self._lock:
            if self.failed is not None or self._file is None:
                return
            buf = self._partial[direction]
            buf += data
            now = time.time()
            lines = []
            while (end := buf.find(0)) >= 0:
                frame, buf[:] = bytes(buf[:end + 1]), buf[end + 1:]
                if len(frame) > 1:  # a lone delimiter is no frame
                    lines.append(f"{now:.6f} {direction} {frame.hex(' ')}\n")
            if not lines:
                return
            try:
                self._file.write("".join(lines))
                self._file.flush()
            except (OSError, ValueError) as exc:
                self.failed = f"{self.path}: cannot write the frame log: {exc}"
                return
            self.frames += len(lines)

    def close(self) -> None:
        with self._lock:
            file, self._file = self._file, None
        if file is not None:
            try:
                file.close()
            except OSError as exc:
                self.failed = self.failed or f"{self.path}: cannot close the frame log: {exc}"

    def describe(self) -> dict[str, object]:
        return {"path": self.path, "frames": self.frames, "failed": self.failed}


def read_serial_log(path: str | Path) -> list[tuple[float, str, bytes]]:
    """``(time, "TX" or "RX", stuffed frame with its delimiter)`` of each line
    of a serial frame log.  ValueError for a line that is not one."""
    out = []
    for n, line in enumerate(Path(path).read_text(encoding="ascii").splitlines(), 1):
        stamp, direction, *hexes = line.split(" ")
        if direction not in ("TX", "RX") or not hexes:
            raise ValueError(f"{path}:{n}: not TIME TX|RX HEX...")
        out.append((float(stamp), direction, bytes.fromhex("".join(hexes))))
    return out
