"""The motor board's simulation-only messages (docs/protocol.md, section 2).

Only fake boards answer them, and only the simulation's side of the host
(``stairbot.fakes.lockstep``) sends them; a real board answers each with
Ack(NOT_SUPPORTED).  They travel on the same wire as the real boards'
messages: importing this module adds them to the codec, and their CAN frames
(``stairbot_sim.dbc``, beside this module) to the CAN wire
(:func:`stairbot.drivers.messages.register`).  A process that never imports
the fakes does not know them: the real driver path never names them.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources

from stairbot.drivers.messages import Message, register

DBC_NAME = "stairbot_sim.dbc"

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


register(StepTo, GetTruth, StepDone, Truth,
         dbc=resources.files("stairbot.fakes").joinpath(DBC_NAME).read_text())
