"""The fake motor board's motor faults (docs/protocol.md, section 3,
"Faults"): a snapshot motor's fault in the protocol's code, and each
motor's latch.  LIMIT (a lift at the end of its stroke) is reported in the
motor's telemetry and never latched; OVERCURRENT, STALL, ENCODER and
DRIVER latch until Clear 0x04."""

from __future__ import annotations

from stairbot.drivers import messages as m
from stairbot.hardware import Snapshot

LATCHING = (m.MotorFault.OVERCURRENT, m.MotorFault.STALL, m.MotorFault.ENCODER,
            m.MotorFault.DRIVER)


def wire_fault(text: str | None) -> m.MotorFault:
    """A snapshot motor's fault as a MotorFault: NONE for none, LIMIT for a
    lift at the end of its stroke ("limit" in the text), the latching fault
    the text names ("overcurrent", "stall", "encoder", as the host's
    ``units.fault_name`` spells them), DRIVER for anything else."""
    if not text:
        return m.MotorFault.NONE
    text = text.lower()
    if "limit" in text:
        return m.MotorFault.LIMIT
    return next((f for f in LATCHING if f.name.lower() in text), m.MotorFault.DRIVER)


class FaultLatch:
    """Each motor's latched fault (NONE: none), in ``messages.MOTOR_CHANNELS``
    order, and the first one latched (Status.fault's)."""

    def __init__(self) -> None:
        self.motors = [m.MotorFault.NONE] * len(m.MOTOR_CHANNELS)
        self.first = m.MotorFault.NONE

    def held(self, ch: int) -> bool:
        """Whether motor ``ch`` has a fault latched."""
        return self.motors[ch] != m.MotorFault.NONE

    def see(self, snap: Snapshot | None) -> list[int]:
        """Latch the faults ``snap`` reports; the channels that latched one now."""
        new = []
        for ch, mid in enumerate(m.MOTOR_CHANNELS):
            fault = wire_fault(snap.motors[mid].fault) if snap else m.MotorFault.NONE
            if fault in LATCHING and not self.held(ch):
                self.motors[ch] = fault
                self.first = self.first or fault
                new.append(ch)
        return new

    def of(self, ch: int, snap: Snapshot | None) -> m.MotorFault:
        """Motor ``ch``'s fault for its telemetry: latched, else LIMIT, else NONE."""
        if self.held(ch) or snap is None:
            return self.motors[ch]
        return wire_fault(snap.motors[m.MOTOR_CHANNELS[ch]].fault)  # LIMIT or NONE

    def clear(self) -> None:
        """Clear 0x04: every motor's latch reset."""
        self.motors = [m.MotorFault.NONE] * len(m.MOTOR_CHANNELS)
        self.first = m.MotorFault.NONE
