"""A motor fault crosses either wire alike (docs/protocol.md, section 3,
"Faults"): the host reads a lift at its limit as "limit" while it is there,
and a latching fault as that motor's, held after the motor stops reporting
it until the host clears the faults."""

from __future__ import annotations

import pytest
from scripted_boards import WIRES, Scripted, link_to, scripted_world, wired

from stairbot.drivers import messages as m
from stairbot.drivers.handshake import latch_names
from stairbot.errors import LatchedError
from stairbot.fakes.boards import make_boards
from stairbot.fakes.lockstep import LockstepRobot
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


@pytest.mark.parametrize("kind", WIRES)
def test_a_motor_fault_left_latched_is_a_latch_the_next_host_is_told_of_and_clears(
        kind: str) -> None:
    world = scripted_world()
    assert isinstance(world.robot, Scripted)
    boards = make_boards(world)
    url = f"{kind}://inline?lockstep=1"
    with link_to(kind, world, boards) as link:
        host = LockstepRobot(link, url)
        world.robot.motor_faults = {MotorId.MWB: "stall"}
        host.clock.advance(0.02)
        host.read()
        world.robot.motor_faults = {}
        host.close()  # gone without a Clear: the stall stays latched
    with link_to(kind, world, boards) as link, pytest.raises(LatchedError) as refused:
        LockstepRobot(link, url)
    assert "STALL motor fault latched" in str(refused.value)
    assert "stairbot clear" in str(refused.value)
    with link_to(kind, world, boards) as link:
        host = LockstepRobot(link, url, allow_latched=True)
        try:
            assert host.latched == {int(m.Board.MOTOR): m.StatusFlag.FAULT}
            assert "STALL motor fault" in latch_names(host.latched[int(m.Board.MOTOR)],
                                                      host.status[m.Board.MOTOR].fault)
            host.clear(m.ClearMask.ALL)
            host.clock.advance(0.02)
            host.read()
            assert not host.status[m.Board.MOTOR].flags & m.StatusFlag.FAULT
        finally:
            host.close()
