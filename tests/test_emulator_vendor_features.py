"""What the vendors' example programs exercise, through the real SDKs, on the emulator.

The ROBOTIS DynamixelSDK protocol 2.0 examples (ping, broadcast ping, read/write, sync and
bulk read/write, fast sync/bulk read, reboot, factory reset, clear multi-turn, indirect
address) and Feetech's SDK examples (ping, read/write, sync write, sync read/write) were
read to learn what they expect; these tests are the project's own. Expected values come
from the ROBOTIS e-Manual (XL430-W250 control table, Protocol 2.0) and the Feetech STS
memory table, with addresses spelled out here on purpose (independent of both tables).
"""

from __future__ import annotations

import faulthandler
import time
from collections.abc import Callable, Iterator
from typing import Any

import dynamixel_sdk as dxl
import pytest
import scservo_sdk as scs
import sdk_link
from sdk_link import ok
from sdk_timeouts import allow_slow_replies

from sim.emulator.chain import Emulator

BAUD = 1_000_000
IDS = [1, 2, 3]
# XL430-W250 (e-Manual): address, size
X_BAUD, X_DELAY, X_MODE, X_TORQUE, X_LED = 8, 9, 11, 64, 65
X_REGISTERED, X_PROFILE_VEL, X_GOAL, X_MOVING = 69, 112, 116, 122
X_PRESENT_VEL, X_PRESENT = 128, 132
X_INDIRECT_ADDRESS_1, X_INDIRECT_DATA_1 = 168, 224
X_ERR_ACCESS = 7
# STS3215 (Feetech memory table)
S_MODEL, S_DELAY, S_LEVEL, S_TORQUE, S_GOAL, S_SPEED = 3, 7, 8, 40, 42, 46
S_ASYNC_FLAG, S_PRESENT, S_PRESENT_SPEED = 64, 56, 58


@pytest.fixture(autouse=True)
def patient_sdks(monkeypatch: pytest.MonkeyPatch) -> None:
    """The SDKs wait for replies as through a slow adapter (tests/sdk_timeouts.py)."""
    allow_slow_replies(monkeypatch)


@pytest.fixture(autouse=True)
def watchdog() -> Iterator[None]:
    faulthandler.dump_traceback_later(30.0, exit=True)
    yield
    faulthandler.cancel_dump_traceback_later()


def served(protocol: str) -> Iterator[tuple[Emulator, Any, Any]]:
    """Three servos (ids 1-3, 1 Mbps) and an open SDK port with its packet handler."""
    yield from sdk_link.served(protocol, IDS, BAUD)


@pytest.fixture
def dx() -> Iterator[tuple[Emulator, Any, Any]]:
    yield from served("dynamixel")


@pytest.fixture
def st() -> Iterator[tuple[Emulator, Any, Any]]:
    yield from served("feetech")


def until(cond: Callable[[], bool], seconds: float = 5.0) -> bool:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(0.02)
    return False


def signed32(v: int) -> int:
    return v - (1 << 32) if v >= 1 << 31 else v


# ------------------------------------------------------------------ Dynamixel 2.0
def test_ping_and_broadcast_ping(dx: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = dx
    assert ph.ping(port, 2)[:3] == (1060, 0, 0)          # XL430-W250 model number
    found, result = ph.broadcastPing(port)
    assert result == dxl.COMM_SUCCESS and sorted(found) == IDS
    assert all(model == 1060 for model, _ in found.values())


def test_read_write_moves_and_reports_velocity(dx: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = dx
    assert ph.write4ByteTxRx(port, 1, X_PROFILE_VEL, 20) == (0, 0)   # 20 x 0.229 rev/min
    assert ph.write1ByteTxRx(port, 1, X_TORQUE, 1) == (0, 0)
    sent = time.monotonic()
    assert ph.write4ByteTxRx(port, 1, X_GOAL, 2048 + 600) == (0, 0)
    assert until(lambda: ok(ph.read1ByteTxRx(port, 1, X_MOVING)) == 1)   # on its way
    assert signed32(ok(ph.read4ByteTxRx(port, 1, X_PRESENT_VEL))) == 20
    # 20 x 0.229 rev/min = 312.6 ticks/s: 600 ticks take ~1.9 s, not 0.15 s at full speed.
    # Bounded by the time since the goal was sent (a busy machine only loosens it).
    assert until(lambda: ok(ph.read4ByteTxRx(port, 1, X_PRESENT)) > 2048)
    present = ok(ph.read4ByteTxRx(port, 1, X_PRESENT))
    assert present - 2048 <= 20 * 0.229 / 60 * 4096 * (time.monotonic() - sent) + 1
    assert ph.write4ByteTxRx(port, 1, X_PROFILE_VEL, 0) == (0, 0)      # 0: no limit
    assert until(lambda: ok(ph.read4ByteTxRx(port, 1, X_PRESENT)) == 2648)
    assert ok(ph.read4ByteTxRx(port, 1, X_PRESENT_VEL)) == 0
    assert ph.write4ByteTxRx(port, 1, X_GOAL, 2000) == (0, 0)
    assert signed32(ok(ph.read4ByteTxRx(port, 1, X_PRESENT_VEL))) < 0


def test_sync_and_fast_sync_read_write(dx: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = dx
    write = dxl.GroupSyncWrite(port, ph, X_TORQUE, 1)
    for i in IDS:
        write.addParam(i, [1])
    assert write.txPacket() == 0
    goals = dxl.GroupSyncWrite(port, ph, X_GOAL, 4)
    for i in IDS:
        goals.addParam(i, list((2048 + 100 * i).to_bytes(4, "little")))
    assert goals.txPacket() == 0
    for fast in (False, True):
        read = dxl.GroupSyncRead(port, ph, X_PRESENT, 4)
        for i in IDS:
            read.addParam(i)

        def arrived(read: Any = read, fast: bool = fast) -> bool:
            assert (read.fastSyncRead() if fast else read.txRxPacket()) == 0
            return all(read.getData(i, X_PRESENT, 4) == 2048 + 100 * i for i in IDS)
        assert until(arrived)


def test_bulk_and_fast_bulk_read_write(dx: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = dx
    write = dxl.GroupBulkWrite(port, ph)
    write.addParam(1, X_LED, 1, [1])
    write.addParam(2, X_PROFILE_VEL, 4, list((7).to_bytes(4, "little")))
    assert write.txPacket() == 0
    for fast in (False, True):
        read = dxl.GroupBulkRead(port, ph)
        read.addParam(1, X_LED, 1)
        read.addParam(2, X_PROFILE_VEL, 4)
        assert (read.fastBulkRead() if fast else read.txRxPacket()) == 0
        assert read.getData(1, X_LED, 1) == 1 and read.getData(2, X_PROFILE_VEL, 4) == 7


def test_reboot_is_a_power_cycle(dx: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = dx
    assert ph.write1ByteTxRx(port, 3, X_TORQUE, 1) == (0, 0)
    assert ph.write1ByteTxRx(port, 3, X_LED, 1) == (0, 0)
    assert ph.reboot(port, 3) == (0, 0)
    assert ok(ph.read1ByteTxRx(port, 3, X_TORQUE)) == 0     # RAM back to its initial 0
    assert ok(ph.read1ByteTxRx(port, 3, X_LED)) == 0


def test_factory_reset_options(dx: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = dx
    assert ph.write1ByteTxRx(port, 2, X_DELAY, 5) == (0, 0)
    assert ph.factoryReset(port, 2, 0x02) == (0, 0)         # all but ID and baud
    assert ok(ph.read1ByteTxRx(port, 2, X_DELAY)) == 250    # the manual's initial value
    assert ph.factoryReset(port, 1, 0xFF) == (0, 0)         # everything: id 1, 57600
    assert ph.ping(port, 1)[1] == dxl.COMM_RX_TIMEOUT
    assert port.setBaudRate(57600)
    assert ok(ph.read1ByteTxRx(port, 1, X_BAUD)) == 1
    assert ph.write1ByteTxRx(port, 1, X_BAUD, 3) == (0, 0)  # back to 1 Mbps
    assert port.setBaudRate(BAUD)
    assert ph.ping(port, 1)[1] == 0


def test_clear_multi_turn(dx: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = dx
    assert ph.write1ByteTxRx(port, 1, X_MODE, 4) == (0, 0)  # extended position mode
    assert ph.write1ByteTxRx(port, 1, X_TORQUE, 1) == (0, 0)
    assert ph.write4ByteTxRx(port, 1, X_GOAL, 4096 + 300) == (0, 0)   # past one turn
    assert until(lambda: ok(ph.read4ByteTxRx(port, 1, X_PRESENT)) == 4396)
    assert ph.clearMultiTurn(port, 1) == (0, 0)
    assert ok(ph.read4ByteTxRx(port, 1, X_PRESENT)) == 300


def test_indirect_address(dx: tuple[Emulator, Any, Any]) -> None:
    emu, port, ph = dx
    targets = [X_GOAL + k for k in range(4)] + [X_LED] + [X_PRESENT + k for k in range(4)] + [
        X_MOVING]
    assert ph.write1ByteTxRx(port, 1, X_TORQUE, 1) == (0, 0)
    assert ph.write2ByteTxRx(port, 1, X_INDIRECT_ADDRESS_1, X_GOAL) == (0, X_ERR_ACCESS)
    assert ph.write1ByteTxRx(port, 1, X_TORQUE, 0) == (0, 0)
    for n, target in enumerate(targets):
        assert ph.write2ByteTxRx(port, 1, X_INDIRECT_ADDRESS_1 + 2 * n, target) == (0, 0)
    assert ph.write1ByteTxRx(port, 1, X_TORQUE, 1) == (0, 0)
    write = dxl.GroupSyncWrite(port, ph, X_INDIRECT_DATA_1, 5)      # goal + LED
    write.addParam(1, list((2048 + 50).to_bytes(4, "little")) + [1])
    assert write.txPacket() == 0
    regs = emu.registers(1)
    assert (regs["goal_position"], regs["led"]) == (2098, 1)
    read = dxl.GroupSyncRead(port, ph, X_INDIRECT_DATA_1 + 5, 5)    # present + moving
    read.addParam(1)

    def settled() -> bool:
        assert read.txRxPacket() == 0
        return (read.getData(1, X_INDIRECT_DATA_1 + 5, 4) == 2098
                and read.getData(1, X_INDIRECT_DATA_1 + 9, 1) == 0)
    assert until(settled)


def test_reg_write_then_action(dx: tuple[Emulator, Any, Any]) -> None:
    emu, port, ph = dx
    for i in IDS:
        assert ph.write1ByteTxRx(port, i, X_TORQUE, 1) == (0, 0)
        assert ph.regWriteTxRx(port, i, X_GOAL, 4, list((2148).to_bytes(4, "little"))) == (0, 0)
        assert ok(ph.read1ByteTxRx(port, i, X_REGISTERED)) == 1
    assert [emu.registers(i)["goal_position"] for i in IDS] == [2048] * 3
    assert ph.action(port, dxl.BROADCAST_ID) == dxl.COMM_SUCCESS   # no reply to wait for
    assert until(lambda: [emu.registers(i)["goal_position"] for i in IDS] == [2148] * 3)
    assert ok(ph.read1ByteTxRx(port, 1, X_REGISTERED)) == 0


def test_writes_outside_the_table_get_the_access_error(dx: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = dx
    assert ph.write1ByteTxRx(port, 1, 14, 1) == (0, X_ERR_ACCESS)       # reserved 14..19
    assert ph.write1ByteTxRx(port, 1, 400, 1) == (0, X_ERR_ACCESS)      # between the blocks
    assert ph.write1ByteTxRx(port, 1, 700, 1) == (0, X_ERR_ACCESS)      # past the table
    assert ph.read1ByteTxRx(port, 1, 700)[1:] == (0, X_ERR_ACCESS)


# ------------------------------------------------------------------ Feetech STS
def test_sts_ping_and_model(st: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = st
    assert ph.ping(port, 3) == (777, 0, 0)                     # STS3215
    assert ok(ph.read2ByteTxRx(port, 3, S_MODEL)) == 777


def test_sts_broadcast_ping_answers_from_every_servo(st: tuple[Emulator, Any, Any]) -> None:
    _, port, _ = st
    body = bytes([0xFE, 2, 1])
    port.ser.reset_input_buffer()
    port.writePort(list(b"\xff\xff" + body + bytes([~sum(body) & 0xFF])))
    data = b""
    end = time.monotonic() + 1.0
    while len(data) < 6 * len(IDS) and time.monotonic() < end:
        data += bytes(port.readPort(64))
    packets = [data[i:i + 6] for i in range(0, len(data), 6)]
    assert [p[2] for p in packets] == IDS
    assert all(p[:2] == b"\xff\xff" and p[3:5] == b"\x02\x00" for p in packets)


def test_sts_goal_without_torque_enable_moves(st: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = st
    assert ok(ph.read1ByteTxRx(port, 1, S_TORQUE)) == 0
    assert ph.write2ByteTxRx(port, 1, S_SPEED, 400) == (0, 0)          # 400 steps/s
    # 900 steps at 400 steps/s: 2.25 s on the way, so a busy machine still reads it moving.
    assert ph.write2ByteTxRx(port, 1, S_GOAL, 2048 + 900) == (0, 0)
    assert ok(ph.read1ByteTxRx(port, 1, S_TORQUE)) == 1
    assert until(lambda: ok(ph.read2ByteTxRx(port, 1, S_PRESENT_SPEED)) == 400)   # moving
    assert until(lambda: ok(ph.read2ByteTxRx(port, 1, S_PRESENT)) == 2948, 10.0)
    # Present position is the rounded horn angle: it reads the goal up to half a step
    # (1.25 ms here) before the horn stops, so the speed reads 0 within a moment (waited
    # for as long as the position: a starved emulator answered late in a loaded run).
    seen: list[tuple[int, int]] = []

    def still() -> bool:
        seen.append((ok(ph.read2ByteTxRx(port, 1, S_PRESENT_SPEED)),
                     ok(ph.read2ByteTxRx(port, 1, S_PRESENT))))
        return seen[-1][0] == 0
    assert until(still, 10.0), seen[-5:]
    assert ph.write2ByteTxRx(port, 1, S_GOAL, 2000) == (0, 0)
    assert ok(ph.read2ByteTxRx(port, 1, S_PRESENT_SPEED)) & 0x8000     # bit 15: direction


def test_sts_sync_write_and_sync_read(st: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = st
    write = scs.GroupSyncWrite(port, ph, S_GOAL, 2)
    for i in IDS:
        write.addParam(i, list((1900 + 10 * i).to_bytes(2, "little")))
    assert write.txPacket() == 0
    read = scs.GroupSyncRead(port, ph, S_PRESENT, 2)
    for i in IDS:
        read.addParam(i)

    def arrived() -> bool:
        assert read.txRxPacket() == 0
        return all(read.getData(i, S_PRESENT, 2) == 1900 + 10 * i for i in IDS)
    assert until(arrived)


def test_sts_reg_write_then_action(st: tuple[Emulator, Any, Any]) -> None:
    emu, port, ph = st
    assert ph.regWriteTxRx(port, 2, S_GOAL, 2, [0x00, 0x09]) == (0, 0)   # 2304
    assert ok(ph.read1ByteTxRx(port, 2, S_ASYNC_FLAG)) == 1
    assert emu.registers(2)["goal_position"] == 2048
    assert ph.action(port, scs.BROADCAST_ID) == scs.COMM_SUCCESS   # no reply to wait for
    assert until(lambda: emu.registers(2)["goal_position"] == 2304)
    assert ok(ph.read1ByteTxRx(port, 2, S_ASYNC_FLAG)) == 0


def test_sts_status_return_level_zero_still_answers_reads(
        st: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = st
    assert ph.write1ByteTxRx(port, 1, S_LEVEL, 0) == (0, 0)   # reply goes out at level 1
    assert ok(ph.read1ByteTxRx(port, 1, S_DELAY)) == 0        # 0: ping and read only
    assert ph.write1ByteTxRx(port, 1, S_DELAY, 0)[0] == scs.COMM_RX_TIMEOUT


def test_multi_port_two_chains_at_once() -> None:
    with Emulator("dynamixel", ids=[1], baud=BAUD) as a, \
            Emulator("dynamixel", ids=[2], baud=57600) as b:
        ports = [dxl.PortHandler(a.port), dxl.PortHandler(b.port)]
        ph = dxl.PacketHandler(2.0)
        for port, baud in zip(ports, (BAUD, 57600), strict=True):
            assert port.openPort() and port.setBaudRate(baud)
        for port, sid in zip(ports, (1, 2), strict=True):
            assert ph.write1ByteTxRx(port, sid, X_TORQUE, 1) == (0, 0)
            assert ph.write4ByteTxRx(port, sid, X_GOAL, 2048 + 10 * sid) == (0, 0)
        assert until(lambda: [ok(ph.read4ByteTxRx(p, s, X_PRESENT)) for p, s in
                              zip(ports, (1, 2), strict=True)] == [2058, 2068])
        assert ph.ping(ports[0], 2)[1] == dxl.COMM_RX_TIMEOUT    # each chain its own
        for port in ports:
            port.closePort()
