"""Rewrite stairbot/drivers/vectors_serial.json from its frame specs: every
vector's body and wire bytes, and the streams built from them (recipes
below), with this module's encoder.  Run after a change to the serial frame
format, then paste the printed Markdown into docs/protocol.md's "Test
vectors" section (tests/drivers/test_protocol_doc.py checks the two agree).

    python scripts/make_serial_vectors.py [--session 0x5A]
"""

from __future__ import annotations

import argparse
import json
from importlib import resources
from pathlib import Path
from typing import Any

from cobs import cobs

from stairbot.drivers import messages as m
from stairbot.drivers.serial_wire import Frame, crc16, encode_frame, frame_body

PATH = Path(str(resources.files("stairbot.drivers").joinpath("vectors_serial.json")))
PROTOCOL_2_READ_ALL = "04 01 02 10 03 9f 67 00"  # no length byte, bit 4 clear: fixed


def frame_of(spec: dict[str, Any]) -> Frame:
    msgs = tuple(getattr(m, x["type"])(**x["fields"]) for x in spec["messages"])
    return Frame(spec["board"], spec["seq"], msgs, spec["from_board"], spec["session"])


def hexs(data: bytes) -> str:
    return data.hex(" ")


def streams(wire: dict[str, bytes], read_all: Frame) -> tuple[dict[str, bytes], int]:
    ra, ack = wire["read all, motor board"], wire["ack of set all speeds"]
    body = bytearray(frame_body(read_all))
    body[3] ^= 0x01  # the length byte: the CRC no longer matches
    seq = next(s for s in range(256)
               if crc16(frame_body(Frame(1, s, (m.ReadAll(),), False, read_all.session))[:-2])
               & 0xFF == 0)
    zero_crc = encode_frame(Frame(1, seq, (m.ReadAll(),), False, read_all.session))
    return {
        "garbage, then a frame": bytes.fromhex("13 37 ff 00") + ra,
        "bad CRC, then a frame": cobs.encode(bytes(body)) + b"\x00" + ack,
        "truncated frame, then a frame": ra[:5] + b"\x00" + ack,
        "empty frames between frames": b"\x00\x00" + ra + b"\x00" + ack,
        "bytes inserted before the delimiter": zero_crc[:-1] + b"\x01\x01\x00" + ack,
        "a protocol 2 frame": bytes.fromhex(PROTOCOL_2_READ_ALL) + ack,
    }, seq


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--session", type=lambda t: int(t, 0), default=0x5A)
    args = ap.parse_args()
    data = json.loads(PATH.read_text())
    wire: dict[str, bytes] = {}
    for v in data["vectors"]:
        v["frame"]["session"] = args.session
        frame = frame_of(v["frame"])
        v["body_hex"] = hexs(frame_body(frame))
        wire[v["name"]] = encode_frame(frame)
        v["wire_hex"] = hexs(wire[v["name"]])
    read_all = next(frame_of(v["frame"]) for v in data["vectors"]
                    if v["name"] == "read all, motor board")
    built, seq = streams(wire, read_all)
    for s in data["streams"]:
        s["wire_hex"] = hexs(built[s["name"]])
        if s["name"] == "bytes inserted before the delimiter":
            s["meaning"] = (f"ReadAll to the motor board, seq {seq}, whose CRC ends in 0x00, "
                            + s["meaning"].split("whose CRC ends in 0x00, ", 1)[1])
    data["framing"] = ("header addr (bit 4 set), session, seq, len (message bytes); messages; "
                       "CRC; then COBS and one 0x00 delimiter")
    PATH.write_text(json.dumps(data, indent=1) + "\n")
    for v in data["vectors"]:
        print(f"**{v['name']}** — {v['meaning']}\n\n    body: {v['body_hex']}\n"
              f"    wire: {v['wire_hex']}\n")
    for s in data["streams"]:
        print(f"**{s['name']}** — {s['meaning']}\n\n    {s['wire_hex']}\n")


if __name__ == "__main__":
    main()
