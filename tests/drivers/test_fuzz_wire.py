"""benchmarks/fuzz_wire.py, small: it runs clean on the code as it is, and it
does count what it is for (an exception a decoder must not raise, a frame
that got through protocol 2's blind spot)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

from stairbot.drivers import serial_wire

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "fuzz_wire.py"
pytestmark = pytest.mark.skipif(not SCRIPT.exists(), reason="needs the source checkout")


def load() -> ModuleType:
    spec = importlib.util.spec_from_file_location("fuzz_wire", SCRIPT)
    assert spec and spec.loader
    mod = importlib.util.module_from_spec(spec)
    sys.modules["fuzz_wire"] = mod
    spec.loader.exec_module(mod)
    return mod


def test_a_small_fuzz_finds_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    assert load().main(["--frames", "3000", "--seed", "7"]) == 0
    out = capsys.readouterr().out
    assert "failures: 0" in out and "serial decoders" in out and "fake boards" in out


def test_it_counts_an_exception_a_decoder_must_not_raise(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    fuzz = load()

    def fragile(stuffed: bytes) -> serial_wire.Frame:
        if len(stuffed) % 7 == 3:
            raise IndexError("a decoder bug")
        return serial_wire.decode_frame(stuffed)

    monkeypatch.setattr(fuzz, "decode_frame", fragile)
    assert fuzz.main(["--frames", "500", "--only", "serial"]) == 1
    out = capsys.readouterr().out
    assert "unexpected" in out and "IndexError: a decoder bug" in out


def test_it_counts_the_blind_spot_on_protocol_2_framing(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """With the length check taken out (as in protocol 2), ``01 01`` before the
    delimiter gets frames through, and the script says so."""
    fuzz = load()
    body = serial_wire.parse_body

    def no_length_check(data: bytes) -> serial_wire.Frame:
        if len(data) >= 7 and serial_wire.crc16(data[:-2]) == int.from_bytes(data[-2:], "big"):
            data = data[:3] + bytes((len(data) - 6,)) + data[4:]
            data = data[:-2] + serial_wire.crc16(data[:-2]).to_bytes(2, "big")
        return body(data)

    monkeypatch.setattr(serial_wire, "parse_body", no_length_check)
    assert fuzz.main(["--frames", "20000", "--only", "serial"]) == 1
    assert "blind spot" in capsys.readouterr().out
