"""The plant link's Python end (stairbot/fakes/plant_link.py): frames, and
what it answers a board from the simulated world.  The C end is exercised
against it by tests/firmware/test_firmware_boards.py."""

from __future__ import annotations

import struct

import pytest
from cobs import cobs

from stairbot.control.robot_config import load_config
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.plant_link import PlantLink, PlantLinkError, decode, encode
from stairbot.fakes.sim import motor_limits
from stairbot.inputs.scenario import load_scenario

CONFIG = load_config()


def link(board: int, lockstep: bool = True) -> PlantLink:
    world = make_world(CONFIG, load_scenario(), lockstep=lockstep)
    return PlantLink(world, board, 4321, motor_limits(CONFIG))


def answers(plant: PlantLink, *frames: bytes) -> list[tuple[int, int, bytes]]:
    out = plant.feed(b"".join(frames))
    return [decode(wire) for wire in out.split(b"\x00") if wire]


def test_a_frame_decodes_to_what_was_encoded_and_a_flipped_bit_fails_its_crc() -> None:
    wire = encode(ord("Q"), 7, b"\x00\x01\x02")
    assert wire.endswith(b"\x00") and b"\x00" not in wire[:-1]
    assert decode(wire[:-1]) == (ord("Q"), 7, b"\x00\x01\x02")
    body = bytearray(cobs.decode(wire[:-1]))
    body[2] ^= 0x10
    with pytest.raises(PlantLinkError, match="CRC"):
        decode(cobs.encode(bytes(body)))


def test_hello_gives_the_board_its_serial_lockstep_channels_and_speed_limits() -> None:
    plant = link(1)
    [(kind, seq, fields)] = answers(plant, encode(ord("H"), 3, b"\x01"))
    board, serial, lockstep, channels, *limits = struct.unpack("<BHBB6h", fields)
    assert (chr(kind), seq, board, serial, lockstep, channels) == ("h", 3, 1, 4321, 1, 6)
    wheel, lift = CONFIG.motors.wheel_speed, CONFIG.motors.lift_speed
    assert limits == [round(wheel * 1000)] * 4 + [round(lift * 1000)] * 2
    assert plant.greeted


def test_a_hello_from_the_other_board_is_refused_and_counted() -> None:
    plant = link(2)
    assert answers(plant, encode(ord("H"), 1, b"\x01")) == []
    assert plant.stats.bad == 1 and not plant.greeted


def test_a_motor_command_and_a_step_move_the_counters_the_next_query_reports() -> None:
    plant = link(1)
    speed = struct.pack("<BhB", 0, 800, 0)  # MWF at 0.8 turn/s
    before = answers(plant, encode(ord("Q"), 1, b"\x00"))[0][2]
    [(kind, _, stepped)] = answers(plant, encode(ord("M"), 0, speed),
                                   encode(ord("S"), 2, struct.pack("<I", 500_000)))
    assert chr(kind) == "s" and struct.unpack("<BI", stepped) == (1, 500_000)
    after = answers(plant, encode(ord("Q"), 3, b"\x00"))[0][2]
    (t0, failed0), (t1, failed1) = struct.unpack_from("<QB", before), struct.unpack_from("<QB",
                                                                                          after)
    turns0, turns1 = struct.unpack_from("<i", before, 9)[0], struct.unpack_from("<i", after, 9)[0]
    assert (t1 - t0, failed0, failed1) == (500_000, 0, 0)
    assert 250 < turns1 - turns0 <= 400  # 0.5 s at 0.8 turn/s, less the start's spin-up
    assert plant.stats.commands == 1 and plant.stats.steps == 1


def test_a_plant_in_real_time_refuses_step_to() -> None:
    plant = link(1, lockstep=False)
    [(_, _, stepped)] = answers(plant, encode(ord("S"), 5, struct.pack("<I", 1000)))
    assert struct.unpack("<BI", stepped) == (0, 0)


def test_the_sensor_state_holds_every_channel_and_the_imu() -> None:
    plant = link(2)
    [(kind, _, fields)] = answers(plant, encode(ord("Q"), 9, b"\x00"))
    now_us, failed, channels = struct.unpack_from("<QBB", fields)
    assert chr(kind) == "n" and (failed, channels) == (0, 4)
    for ch in range(channels):
        measured, code, mm, at_us = struct.unpack_from("<BBHI", fields, 10 + 8 * ch)
        assert measured == 1 and code in (0, 1, 2) and at_us <= now_us
    imu_at = 10 + 8 * channels
    fitted = fields[imu_at]
    assert len(fields) == imu_at + 1 + 2 * 9 and fitted in (0, 1)
