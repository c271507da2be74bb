"""The motor board's simulation-only messages (docs/protocol.md, section 2).

Only fake boards (``stairbot.fakes``) answer them, and only the simulation's
side of the host (``stairbot.fakes.lockstep``) sends them; a real board answers
each with Ack(NOT_SUPPORTED).  They are defined here, beside the real boards'
messages, because they travel on the same wire: the codec and the CAN
database know their type codes and ids, so one wire serves both.  The host's
real driver path (``board_robot``, the links) never names them.
"""

from __future__ import annotations

from dataclasses import dataclass

from stairbot.drivers.records import Message

STEP_DONE, TRUTH = 0xFE, 0xFD
FELL = 0x01  # Truth.flags: the simulated robot fell


@dataclass(frozen=True, slots=True)
class StepTo(Message):
    """Simulation only (LOCKSTEP fake boards): advance the simulated world to
    ``time_us`` microseconds since start; earlier times are a no-op, so the
    message is idempotent.  Sent to the motor board.  Reply: StepDone."""

    TYPE = 0x7E
    ANSWER = STEP_DONE
    FORMAT = "<I"
    IDEMPOTENT = True
    time_us: int


@dataclass(frozen=True, slots=True)
class GetTruth(Message):
    """Simulation only: ask the fake boards for the simulated world's truth
    (not something a real robot knows).  Sent to the motor board.  Reply: Truth."""

    TYPE = 0x7D
    ANSWER = TRUTH
    IDEMPOTENT = True


@dataclass(frozen=True, slots=True)
class StepDone(Message):
    TYPE = 0xFE
    FORMAT = "<I"
    REPLY = True
    time_us: int


@dataclass(frozen=True, slots=True)
class Truth(Message):
    """Simulation only: bit 0 of ``flags`` = the robot fell; the largest pitch
    so far in centi-degrees; the robot's offset from its start in mm."""

    TYPE = 0xFD
    FORMAT = "<Bxhi"
    REPLY = True
    flags: int
    max_pitch_cdeg: int
    offset_mm: int
