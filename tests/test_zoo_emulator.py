"""The emulated XL-320, SCS and dual-axis servos answer the vendor SDKs as their manuals
say. Addresses, values and error codes are written out here from the manuals (e-Manual
XL-320 and 2XL430-W250 pages, "Protocol 2.0" status errors; the SCS15 manual and Feetech's
SCSCL.h), not read from any table of the project.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import dynamixel_sdk as dxl
import pytest
import scservo_sdk as scs
from sdk_timeouts import allow_slow_replies

from sim.emulator.chain import Emulator

# e-Manual XL-320 control table.
XL_ID, XL_TORQUE, XL_LED, XL_CONTROL_MODE = 3, 24, 25, 11
XL_GOAL, XL_MOVING_SPEED, XL_PRESENT, XL_HW_ERROR, XL_CCW_LIMIT = 30, 32, 37, 50, 8
# e-Manual "Protocol 2.0", Status Packet error field.
DATA_RANGE, DATA_LIMIT, ALERT = 0x04, 0x06, 0x80
# SCS15 manual / SCSCL.h.
SCS_ID, SCS_MIN_LIMIT, SCS_MAX_LIMIT, SCS_TORQUE, SCS_GOAL, SCS_LOCK = 5, 9, 11, 40, 42, 48
SCS_PRESENT, SCS_STATUS = 56, 65
# e-Manual 2XL430-W250 (the X table).
X_ID, X_BAUD = 7, 8


@pytest.fixture(autouse=True)
def patient_sdks(monkeypatch: pytest.MonkeyPatch) -> None:
    allow_slow_replies(monkeypatch)


def _port(emu: Emulator, sdk: Any, baud: int = 1_000_000) -> Any:
    port = sdk.PortHandler(emu.port)
    assert port.openPort() and port.setBaudRate(baud)
    return port


@pytest.fixture
def xl320() -> Iterator[tuple[Emulator, Any, Any]]:
    with Emulator("dynamixel", ids=[1, 2], model="XL-320") as emu:
        port = _port(emu, dxl)
        yield emu, port, dxl.PacketHandler(2.0)
        port.closePort()


def test_xl320_answers_at_its_own_addresses(xl320: tuple[Emulator, Any, Any]) -> None:
    emu, port, ph = xl320
    assert ph.ping(port, 1)[:2] == (350, 0)                       # Model Number 350
    assert ph.read2ByteTxRx(port, 1, XL_CCW_LIMIT)[0] == 1023
    assert ph.write1ByteTxRx(port, 1, XL_LED, 7) == (0, 0)       # LED: 0-7, three colours
    assert ph.write1ByteTxRx(port, 1, XL_TORQUE, 1) == (0, 0)
    assert ph.write2ByteTxRx(port, 1, XL_GOAL, 600) == (0, 0)
    assert ph.write2ByteTxRx(port, 1, XL_GOAL, 1024)[1] == DATA_LIMIT   # past CCW Angle Limit
    deadline_ok = False
    for _ in range(200):                                          # it moves toward 600
        if ph.read2ByteTxRx(port, 1, XL_PRESENT)[0] == 600:
            deadline_ok = True
            break
    assert deadline_ok
    # EEPROM while torque is on: Access Error (7), as on the X series
    assert ph.write1ByteTxRx(port, 1, XL_ID, 9)[1] == 0x07


def test_xl320_hardware_error_latches_and_drops_torque(
        xl320: tuple[Emulator, Any, Any]) -> None:
    emu, port, ph = xl320
    assert ph.write1ByteTxRx(port, 2, XL_TORQUE, 1) == (0, 0)
    emu.set_faults(hw_error={2: "overheating"})
    value, comm, error = ph.read1ByteTxRx(port, 2, XL_HW_ERROR)
    assert (value, comm, error) == (0x02, 0, ALERT)     # Shutdown bit 1: OverHeating
    assert ph.read1ByteTxRx(port, 2, XL_TORQUE)[0] == 0
    emu.set_faults(hw_error={2: "voltage"})
    assert ph.read1ByteTxRx(port, 2, XL_HW_ERROR)[0] == 0x02 | 0x04    # latched + voltage


def test_xl320_wheel_mode_is_control_mode_1(xl320: tuple[Emulator, Any, Any]) -> None:
    emu, port, ph = xl320
    assert ph.write1ByteTxRx(port, 1, XL_CONTROL_MODE, 1) == (0, 0)
    assert ph.write1ByteTxRx(port, 1, XL_TORQUE, 1) == (0, 0)
    start = ph.read2ByteTxRx(port, 1, XL_PRESENT)[0]
    assert ph.write2ByteTxRx(port, 1, XL_MOVING_SPEED, 512) == (0, 0)   # 50 % CCW
    moved = False
    for _ in range(200):
        if ph.read2ByteTxRx(port, 1, XL_PRESENT)[0] != start:
            moved = True
            break
    assert moved


def test_scs_words_are_big_endian_on_the_wire() -> None:
    with Emulator("feetech", ids=[1], model="SCS15") as emu:
        port = _port(emu, scs)
        ph = scs.PacketHandler(1)                   # the SDK in SCS (big-endian) mode
        try:
            emu.set_register(1, "present_position", 0x0123)
            data, comm, _ = ph.readTxRx(port, 1, SCS_PRESENT, 2)
            assert comm == 0 and list(data) == [0x01, 0x23]       # high byte first
            assert ph.read2ByteTxRx(port, 1, SCS_MAX_LIMIT)[0] == 1023
            # a goal outside the angle limits is clamped (SCS15 manual: "it is equal to
            # the limit value"), and a goal write energises the servo
            assert ph.write2ByteTxRx(port, 1, SCS_MIN_LIMIT, 100) == (0, 0)
            assert ph.write2ByteTxRx(port, 1, SCS_GOAL, 50) == (0, 0)
            assert ph.read2ByteTxRx(port, 1, SCS_GOAL)[0] == 100
            assert ph.read1ByteTxRx(port, 1, SCS_TORQUE)[0] == 1
            emu.set_faults(hw_error={1: "overload"})
            assert ph.read1ByteTxRx(port, 1, SCS_STATUS)[0] == 0x20       # BIT5 load
        finally:
            scs.SCS_SETEND(0)
            port.closePort()


def test_scs_eeprom_is_kept_only_with_lock_48_at_0() -> None:
    with Emulator.factory_new("feetech", 2, model="SCS0009") as emu:
        port = _port(emu, scs)
        ph = scs.PacketHandler(1)
        try:
            for index, unlock in ((0, False), (1, True)):
                emu.plug(index)
                if unlock:
                    assert ph.write1ByteTxRx(port, 1, SCS_LOCK, 0) == (0, 0)
                assert ph.write1ByteTxRx(port, 1, SCS_ID, 5) == (0, 0)
                emu.plug(None)                     # power-cycle: off, then on again
                emu.plug(index)
                assert emu.registers_of(index)["id"] == (5 if unlock else 1)
        finally:
            scs.SCS_SETEND(0)
            port.closePort()


def test_a_dual_axis_case_shares_its_baud_and_refuses_one_id_for_both() -> None:
    with Emulator.factory_new("dynamixel", 1, model="2XL430-W250") as emu:
        assert emu.ids == (1, 2)                         # two axes, ids 1 and 2
        emu.plug(0)                                      # the whole case
        port = _port(emu, dxl, 57_600)
        ph = dxl.PacketHandler(2.0)
        try:
            assert [ph.ping(port, i)[:2] for i in (1, 2)] == [(1090, 0), (1090, 0)]
            assert ph.write1ByteTxRx(port, 1, X_ID, 2)[1] == DATA_LIMIT   # the other's id
            assert ph.write1ByteTxRx(port, 1, X_ID, 5) == (0, 0)
            ph.write1ByteTxRx(port, 5, X_BAUD, 3)        # 1 Mbps, on one axis only
            assert port.setBaudRate(1_000_000)
            assert [ph.ping(port, i)[:2] for i in (5, 2)] == [(1090, 0), (1090, 0)]
        finally:
            port.closePort()
