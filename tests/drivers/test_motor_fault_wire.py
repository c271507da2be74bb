"""A motor fault crosses either wire alike (docs/protocol.md, section 3,
"Faults"): the host reads a lift at its limit as "limit" while it is there,
and a latching fault as that motor's, held after the motor stops reporting
it until the host clears the faults."""

from __future__ import annotations

import pytest
from scripted_boards import WIRES, wired

from stairbot.drivers import messages as m
from stairbot.hardware import MotorId


@pytest.mark.parametrize("kind", WIRES)
def test_a_latched_motor_fault_reaches_the_host_until_it_clears_it(kind: str) -> None:
    with wired(kind) as (host, robot, _):
        robot.motor_faults = {MotorId.MTF: "lift limit", MotorId.MWB: "stall"}
        host.clock.advance(0.02)
        snap = host.read()
        faults = {mid: s.fault for mid, s in snap.motors.items() if s.fault}
        assert faults == {MotorId.MTF: "limit", MotorId.MWB: "stall"}
        robot.motor_faults = {}
        host.clock.advance(0.02)
        faults = {mid: s.fault for mid, s in host.read().motors.items() if s.fault}
        assert faults == {MotorId.MWB: "stall"}  # latched; LIMIT went with the limit
        assert host.status[m.Board.MOTOR].flags & m.StatusFlag.FAULT
        host.clear(m.ClearMask.FAULTS)
        host.clock.advance(0.02)
        assert not any(s.fault for s in host.read().motors.values())
        assert not host.status[m.Board.MOTOR].flags & m.StatusFlag.FAULT
