"""Two other people's STS3215 libraries, st3215 and feetech-cli, through their own centring,
set-zero and wheel-mode features against the emulator (the rest: docs/third_party.md).

Expected values are the STS memory table's relations, written here: Present Position =
(raw - Position correction(31)) mod 4096; Torque Enable(40) = 128 makes the present position
read 2048; in constant-speed mode (33 = 1) Present Speed(58) follows Goal Speed(46).
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest
import st3215  # type: ignore[import-untyped]
import st3215.port_handler  # type: ignore[import-untyped]
from feetech_cli.controller import FeetechServoController  # type: ignore[import-untyped]
from waiting import wait_for

from sim.emulator.chain import Emulator

BAUD = 1_000_000


@pytest.fixture
def port(monkeypatch: pytest.MonkeyPatch) -> Iterator[str]:
    # st3215 waits 50 ms for a reply: too short for a loaded 2-core test machine.
    monkeypatch.setattr(st3215.port_handler, "LATENCY_TIMER", 300)
    with Emulator("feetech", ids=[1, 2], baud=BAUD) as emu:
        yield emu.port


def test_st3215_define_middle_correct_position_and_rotate(port: str) -> None:
    s = st3215.ST3215(port)
    s.WritePosition(1, 2300)
    assert wait_for(lambda: s.ReadPosition(1) == 2300)
    assert s.DefineMiddle(1) is True                      # Torque Enable = 128
    assert s.ReadPosition(1) == 2048
    assert s.ReadCorrection(1) == 2300 - 2048             # present = raw - correction
    s.CorrectPosition(2, -100)
    assert (s.ReadCorrection(2), s.ReadPosition(2)) == (-100, 2048 + 100)
    s.Rotate(2, -500)                                      # mode 1, speed with bit 15
    assert s.ReadMode(2) == 1
    assert s.ReadSpeed(2)[0] == -500     # st3215 returns (speed, comm, error) here
    s.portHandler.closePort()


def test_feetech_cli_set_zero_and_wheel_mode(port: str) -> None:
    c = FeetechServoController(port, baudrate=BAUD, timeout=0.3)
    c.open()
    try:
        c.set_goal_position(1, 1700)
        assert wait_for(lambda: c.read_register(1, "present_position") == 1700)
        assert c.set_zero(1) == 2048
        assert c.read_register(1, "homing_offset") == 1700 - 2048
        c.set_operating_mode(2, 1)
        c.set_goal_velocity(2, 400)
        assert c.read_register(2, "present_velocity") == 400
        start = c.read_register(2, "present_position")
        assert wait_for(lambda: c.read_register(2, "present_position") != start)
    finally:
        c.close()
