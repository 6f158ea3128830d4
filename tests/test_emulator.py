"""The pty servo emulator, exercised end to end by the REAL vendor SDKs.

Nothing is patched: dynamixel_sdk / scservo_sdk open the pty like a USB adapter.
Every test runs under a faulthandler watchdog, so a hang fails loudly instead of blocking.
"""

from __future__ import annotations

import faulthandler
import os
import select
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import dynamixel_sdk as dxl
import pytest
import scservo_sdk as scs
from hypothesis import given
from hypothesis import strategies as st
from sdk_timeouts import REPLY_WAIT_S, allow_slow_replies

from robot.bus.tables import DYNAMIXEL_X, FEETECH_STS
from robot.config.robot_file import load_robot
from sim.emulator import dxl_protocol, sts_protocol
from sim.emulator.chain import Emulator, EmulatorError

ROOT = Path(__file__).resolve().parent.parent
TEST_TIMEOUT_S = 20.0
DXL_ROBOT = load_robot(ROOT / "configs/robots/biped18-dynamixel.toml")
STS_ROBOT = load_robot(ROOT / "configs/robots/biped18-feetech.toml")
IDS = list(DXL_ROBOT.ids)
X = DYNAMIXEL_X
S = FEETECH_STS
#: Fault name -> error bit, as the manuals print them: ROBOTIS e-Manual XL430-W250
#: "Hardware Error Status(70)"; Feetech STS memory table "Servo status(65)".
BIT = {
    "dynamixel_x": {"voltage": 0x01, "overheating": 0x04, "encoder": 0x08,
                    "electrical_shock": 0x10, "overload": 0x20},
    "feetech_sts": {"voltage": 0x01, "encoder": 0x02, "overheating": 0x04,
                    "overcurrent": 0x08, "overload": 0x20},
}


@pytest.fixture(autouse=True)
def patient_sdks(monkeypatch: pytest.MonkeyPatch) -> None:
    allow_slow_replies(monkeypatch)


@pytest.fixture(autouse=True)
def watchdog() -> Iterator[None]:
    faulthandler.dump_traceback_later(TEST_TIMEOUT_S, exit=True)
    yield
    faulthandler.cancel_dump_traceback_later()


class Link:
    """An emulator plus an open SDK port on it."""

    def __init__(self, emu: Emulator, port: Any, ph: Any, sdk: Any) -> None:
        self.emu, self.port, self.ph, self.sdk = emu, port, ph, sdk

    def ping(self, servo_id: int) -> tuple[int, int, int]:
        model, result, error = self.ph.ping(self.port, servo_id)
        return model, result, error


def open_link(protocol: str, baud: int = 1_000_000, **kwargs: Any) -> Iterator[Link]:
    robot = DXL_ROBOT if protocol == "dynamixel" else STS_ROBOT
    with Emulator(protocol, robot, **kwargs) as emu:
        sdk: Any = dxl if protocol == "dynamixel" else scs
        port = sdk.PortHandler(emu.port)
        ph = dxl.PacketHandler(2.0) if protocol == "dynamixel" else scs.PacketHandler(0)
        assert port.openPort() and port.setBaudRate(baud)
        try:
            yield Link(emu, port, ph, sdk)
        finally:
            if port.is_open:
                try:
                    port.closePort()
                except OSError:
                    pass


@pytest.fixture
def dlink() -> Iterator[Link]:
    yield from open_link("dynamixel")


@pytest.fixture
def slink() -> Iterator[Link]:
    yield from open_link("feetech")


@pytest.fixture(params=["dynamixel", "feetech"])
def link(request: pytest.FixtureRequest) -> Iterator[Link]:
    yield from open_link(request.param)


def goal_reg(link: Link) -> Any:
    return (X if link.sdk is dxl else S)["goal_position"]


def sync_read(link: Link, name: str, ids: list[int], *, fast: bool = False
              ) -> tuple[int, dict[int, int]]:
    reg = (X if link.sdk is dxl else S)[name]
    group = link.sdk.GroupSyncRead(link.port, link.ph, reg.address, reg.size)
    for i in ids:
        assert group.addParam(i)
    result = group.fastSyncRead() if fast else group.txRxPacket()
    return result, {i: group.getData(i, reg.address, reg.size) for i in ids}


def sync_write(link: Link, name: str, values: dict[int, int]) -> int:
    reg = (X if link.sdk is dxl else S)[name]
    group = link.sdk.GroupSyncWrite(link.port, link.ph, reg.address, reg.size)
    for i, v in values.items():
        assert group.addParam(i, list(v.to_bytes(reg.size, "little")))
    return int(group.txPacket())


def near_max_limit(link: Link, servo_id: int) -> int:
    """A goal just inside a servo's upper position limit [ticks]."""
    regs = link.emu.registers(servo_id)
    lo, hi = (("min_position_limit", "max_position_limit") if link.sdk is dxl
              else ("min_angle_limit", "max_angle_limit"))
    return max(regs[lo], regs[hi] - 20)


def within(seconds: float, fn: Callable[[], Any]) -> tuple[bool, Any]:
    """Run ``fn`` in a thread; (finished in time, its result or the exception it raised)."""
    box: list[Any] = []

    def target() -> None:
        try:
            box.append(fn())
        except Exception as e:  # noqa: BLE001 - the test inspects it
            box.append(e)

    t = threading.Thread(target=target, daemon=True)
    t.start()
    t.join(seconds)
    return (not t.is_alive()), (box[0] if box else None)


# ---------------------------------------------------------------------------- codecs


@given(st.binary(max_size=64))
def test_crc_matches_the_sdk_table(data: bytes) -> None:
    assert dxl_protocol.crc16(data) == dxl.PacketHandler(2.0).updateCRC(0, list(data), len(data))


@given(st.lists(st.sampled_from([0x00, 0xFD, 0xFF, 0x55]), max_size=40).map(bytes))
def test_stuffing_round_trips_and_never_leaves_a_header(body: bytes) -> None:
    stuffed = dxl_protocol.stuff(body)
    assert dxl_protocol.unstuff(stuffed) == body
    assert b"\xff\xff\xfd\x00" not in stuffed or b"\xff\xff\xfd\x00" in body


def test_parsers_resync_after_garbage_and_count_bad_checksums() -> None:
    good = dxl_protocol.frame(3, bytes([dxl_protocol.INST_PING]))
    bad = good[:-1] + bytes([good[-1] ^ 1])
    p = dxl_protocol.Parser()
    assert p.feed(b"\x00\xff" + bad + good[:5]) == []
    assert p.feed(good[5:]) == [(3, dxl_protocol.INST_PING, b"")]
    assert p.bad_checksum == 1
    sgood = sts_protocol.status(7, 0, b"\x01\x02")
    q = sts_protocol.Parser()
    assert q.feed(b"\xff" + sgood) == [(7, 0, b"\x01\x02")]


# ---------------------------------------------------------------------------- basics


def test_ping_reports_the_model(link: Link) -> None:
    model, result, error = link.ping(1)
    assert result == 0 and error == 0
    assert model == (1060 if link.sdk is dxl else 777)
    assert link.ping(99)[1] != 0  # nobody there: the SDK times out


def test_dxl_read_write_each_size(dlink: Link) -> None:
    port, ph = dlink.port, dlink.ph
    assert ph.write1ByteTxRx(port, 1, X["led"].address, 1) == (0, 0)
    assert ph.read1ByteTxRx(port, 1, X["led"].address) == (1, 0, 0)
    assert ph.write2ByteTxRx(port, 1, X["max_voltage_limit"].address, 120) == (0, 0)
    assert ph.read2ByteTxRx(port, 1, X["max_voltage_limit"].address) == (120, 0, 0)
    assert ph.write4ByteTxRx(port, 1, X["profile_velocity"].address, 70000) == (0, 0)
    assert ph.read4ByteTxRx(port, 1, X["profile_velocity"].address) == (70000, 0, 0)
    assert ph.read2ByteTxRx(port, 1, X["present_input_voltage"].address) == (115, 0, 0)
    assert ph.read1ByteTxRx(port, 1, X["present_temperature"].address) == (35, 0, 0)
    assert dlink.emu.registers(1)["profile_velocity"] == 70000


def test_sts_read_write_each_size(slink: Link) -> None:
    port, ph = slink.port, slink.ph
    assert ph.write1ByteTxRx(port, 2, S["acceleration"].address, 50) == (0, 0)
    assert ph.read1ByteTxRx(port, 2, S["acceleration"].address) == (50, 0, 0)
    assert ph.write2ByteTxRx(port, 2, S["goal_speed"].address, 1234) == (0, 0)
    assert ph.read2ByteTxRx(port, 2, S["goal_speed"].address) == (1234, 0, 0)
    pos_speed, result, _ = ph.read4ByteTxRx(port, 2, S["present_position"].address)
    assert result == 0 and pos_speed & 0xFFFF == STS_ROBOT.joint("r_hip_roll").zero_ticks
    assert ph.read1ByteTxRx(port, 2, S["present_voltage"].address) == (74, 0, 0)
    assert slink.emu.registers(2)["goal_speed"] == 1234


def test_sync_write_goals_then_present_converges(link: Link) -> None:
    start = time.monotonic()
    assert sync_write(link, "torque_enable", dict.fromkeys(IDS, 1)) == 0
    goals = {i: near_max_limit(link, i) for i in IDS}
    assert sync_write(link, "goal_position", goals) == 0
    result, first = sync_read(link, "present_position", IDS)
    assert result == 0 and any(first[i] != goals[i] for i in IDS)  # not there instantly
    deadline = time.monotonic() + 5.0
    while time.monotonic() < deadline:
        result, present = sync_read(link, "present_position", IDS)
        assert result == 0
        if present == goals:
            break
    assert present == goals
    assert all(goals[i] != 2048 for i in IDS)  # everyone moved
    packets = [p for p in link.emu.log() if p.t >= start]
    writes = [p for p in packets if p.instruction == "sync_write"]
    assert [w.address for w in writes] == [(X if link.sdk is dxl else S)["torque_enable"].address,
                                           goal_reg(link).address]
    assert writes[1].values == goals and writes[1].ids == tuple(IDS)
    assert link.emu.counters()["sync_write"] == 2


def test_motion_follows_the_no_load_speed(dlink: Link) -> None:
    """Mid-travel, every reading is as far as the no-load speed takes the horn: at least
    from when the write was answered to when the reading was asked, at most from when the
    write was sent to when the reading came back (motion runs on the child's clock)."""
    emu = dlink.emu
    emu.set_register(4, "torque_enable", 1)
    speed = 57 * 4096 / 60  # XL430: 57 rpm → ticks/s
    travel = 1400  # within id 4's limits (2048..3548): 0.36 s at the no-load speed
    sent = time.monotonic()
    assert dlink.ph.write4ByteTxRx(dlink.port, 4, X["goal_position"].address,
                                   2048 + travel) == (0, 0)
    answered = time.monotonic()
    checked = 0  # readings taken at least 30 ms into the travel, before it ended
    deadline = answered + 5.0
    while time.monotonic() < deadline:
        asked = time.monotonic()
        moved = emu.registers(4)["present_position"] - 2048
        got = time.monotonic()
        if moved >= travel:
            break
        assert speed * (asked - answered) - 1 <= moved <= speed * (got - sent) + 1
        checked += int(asked - answered >= 0.03)
    assert moved == travel
    assert checked >= 1


def test_sync_read_of_18_servos_and_fast_and_bulk(dlink: Link) -> None:
    zeros = {j.servo_id: j.zero_ticks for j in DXL_ROBOT.joints}
    assert sync_read(dlink, "present_position", IDS) == (0, zeros)
    assert sync_read(dlink, "present_position", IDS, fast=True) == (0, zeros)
    bulk = dxl.GroupBulkRead(dlink.port, dlink.ph)
    regs = {1: X["present_position"], 2: X["present_temperature"], 3: X["model_number"]}
    for i, reg in regs.items():
        assert bulk.addParam(i, reg.address, reg.size)
    assert bulk.txRxPacket() == 0
    got = {i: bulk.getData(i, r.address, r.size) for i, r in regs.items()}
    assert got == {1: zeros[1], 2: 35, 3: 1060}
    last = dlink.emu.log()[-1]
    assert last.instruction == "bulk_read" and last.values == {
        i: r.address for i, r in regs.items()}


def test_sts_sync_read_of_18_servos(slink: Link) -> None:
    zeros = {j.servo_id: j.zero_ticks for j in STS_ROBOT.joints}
    assert sync_read(slink, "present_position", IDS) == (0, zeros)


def test_byte_stuffing_both_directions(dlink: Link) -> None:
    value = 0xFDFFFF01  # little-endian bytes 01 FF FF FD: the SDK must stuff them
    addr = X["profile_acceleration"].address
    before = dlink.emu.counters()["rx_bytes"]
    assert dlink.ph.write4ByteTxRx(dlink.port, 1, addr, value) == (0, 0)
    # 16 bytes + one stuffed FD; dynamixel_sdk 4.1 drops its own stuffing (addStuffing's
    # result is discarded when the length grows), so it sends 16 unstuffed bytes.
    assert dlink.emu.counters()["rx_bytes"] - before in (16, 17)
    assert dlink.emu.log()[-1].values == {1: value}
    assert dlink.ph.read4ByteTxRx(dlink.port, 1, addr) == (value, 0, 0)  # reply stuffed too


def test_dxl_refuses_bad_writes_like_an_x_servo(dlink: Link) -> None:
    port, ph = dlink.port, dlink.ph
    err = dxl_protocol
    assert ph.write4ByteTxRx(port, 1, X["present_position"].address, 5) == (0, err.ERR_ACCESS)
    assert ph.write1ByteTxRx(port, 1, X["torque_enable"].address, 2) == (0, err.ERR_DATA_RANGE)
    limit = dlink.emu.registers(1)["max_position_limit"]
    assert ph.write4ByteTxRx(port, 1, X["goal_position"].address, limit + 1) == (
        0, err.ERR_DATA_LIMIT)
    assert dlink.emu.registers(1)["goal_position"] == 2048
    assert sync_write(dlink, "goal_position", {1: limit + 5, 2: 2050}) == 0  # no status
    assert [dlink.emu.registers(i)["goal_position"] for i in (1, 2)] == [2048, 2050]
    assert ph.write1ByteTxRx(port, 1, X["torque_enable"].address, 1) == (0, 0)
    assert ph.write1ByteTxRx(port, 1, X["return_delay_time"].address, 0) == (0, err.ERR_ACCESS)
    assert ph.read1ByteTxRx(port, 1, 400)[1:] == (0, err.ERR_ACCESS)  # beyond the table


def test_sts_clamps_goal_to_the_angle_limits(slink: Link) -> None:
    hi = slink.emu.registers(1)["max_angle_limit"]
    assert slink.ph.write2ByteTxRx(slink.port, 1, S["goal_position"].address, 4000) == (0, 0)
    assert slink.emu.registers(1)["goal_position"] == hi < 4000


def test_reboot_clears_a_latched_hardware_error(dlink: Link) -> None:
    port, ph = dlink.port, dlink.ph
    dlink.emu.set_faults(hw_error={2: "overheating"})
    assert ph.ping(port, 2)[2] & dxl_protocol.ERR_ALERT
    status, _, _ = ph.read1ByteTxRx(port, 2, X["hardware_error_status"].address)
    assert status == BIT["dynamixel_x"]["overheating"]
    assert ph.write1ByteTxRx(port, 2, X["torque_enable"].address, 1)[0] == 0
    assert dlink.emu.registers(2)["torque_enable"] == 0  # shutdown refuses torque
    dlink.emu.set_faults(hw_error={2: None})
    assert dlink.emu.registers(2)["hardware_error_status"] != 0  # latched until reboot
    assert ph.reboot(port, 2) == (0, dxl_protocol.ERR_ALERT)
    assert ph.ping(port, 2)[1:] == (0, 0)
    assert dlink.emu.registers(2)["hardware_error_status"] == 0
    assert dlink.emu.log()[-2].instruction == "reboot"


def test_return_delay_slows_the_answer(dlink: Link) -> None:
    # The fastest of many pings: a busy machine only ever adds time, so the minimum is the
    # floor with and without the delay (a median moved with the load of other tests).
    def fastest_ping_s(n: int = 30) -> float:
        times = []
        for _ in range(n):
            t = time.perf_counter()
            assert dlink.ping(5)[1] == 0
            times.append(time.perf_counter() - t)
        return min(times)

    fast = fastest_ping_s()
    dlink.emu.set_register(5, "return_delay_time", 250)  # 500 µs
    assert fastest_ping_s() - fast > 0.0003


def test_status_return_level_zero_answers_ping_only(dlink: Link) -> None:
    dlink.emu.set_register(6, "status_return_level", 0)
    assert dlink.ping(6)[1] == 0
    assert dlink.ph.write1ByteTxRx(dlink.port, 6, X["led"].address, 1)[0] == dxl.COMM_RX_TIMEOUT
    assert dlink.emu.registers(6)["led"] == 1  # applied, just not acknowledged


def test_api_errors_are_clear() -> None:
    with pytest.raises(EmulatorError, match="protocol"):
        Emulator("can", ids=[1])
    with pytest.raises(EmulatorError, match="not a dynamixel servo"):
        Emulator("dynamixel", ids=[1], model="STS3215")
    with pytest.raises(EmulatorError, match="baud"):
        Emulator("feetech", ids=[1], baud=4_000_000)
    emu = Emulator("feetech", ids=[1, 2])
    with pytest.raises(EmulatorError, match="not running"):
        emu.counters()
    with emu:
        with pytest.raises(EmulatorError, match="unknown fault"):
            emu.set_faults(hw_error={1: "melted"})
        with pytest.raises(EmulatorError, match="no emulated servo with id 9"):
            emu.registers(9)
        with pytest.raises(EmulatorError, match="not in the feetech_sts table"):
            emu.set_register(1, "hardware_error_status", 1)
    emu.stop()  # idempotent


# ---------------------------------------------------------------------------- faults


def test_drop_all_replies_times_out(link: Link) -> None:
    link.emu.set_faults(drop_rate=1.0)
    t = time.monotonic()
    assert link.ping(1)[1] == link.sdk.COMM_RX_TIMEOUT
    assert time.monotonic() - t < 2 * REPLY_WAIT_S  # the SDK's wait, not a hang
    link.emu.clear_faults()
    assert link.ping(1)[1] == 0
    assert link.emu.counters()["dropped"] == 1


def test_drop_a_share_of_replies(dlink: Link) -> None:
    dlink.emu.set_faults(drop_rate=0.3)
    results = [dlink.ping(1)[1] for _ in range(20)]
    lost = results.count(dxl.COMM_RX_TIMEOUT)
    assert 0 < lost < 20 and lost + results.count(0) == 20
    assert dlink.emu.counters()["dropped"] == lost


def test_corrupt_checksum_is_rx_corrupt(link: Link) -> None:
    link.emu.set_faults(corrupt_rate=1.0)
    assert link.ping(3)[1] == link.sdk.COMM_RX_CORRUPT
    assert link.emu.counters()["corrupted"] >= 1


def test_missing_id_silences_the_rest_of_a_sync_read(link: Link) -> None:
    link.emu.set_faults(missing_ids=[5])
    assert link.ping(5)[1] == link.sdk.COMM_RX_TIMEOUT
    assert link.ping(6)[1] == 0
    before = link.emu.counters()["tx_packets"]
    result, _ = sync_read(link, "present_position", IDS)
    assert result == link.sdk.COMM_RX_TIMEOUT
    assert link.emu.counters()["tx_packets"] - before == 4  # ids 1-4 answered, none after


def test_missing_id_breaks_a_fast_sync_read(dlink: Link) -> None:
    dlink.emu.set_faults(missing_ids=[9])
    result, _ = sync_read(dlink, "present_position", IDS, fast=True)
    assert result in (dxl.COMM_RX_CORRUPT, dxl.COMM_RX_TIMEOUT)


def test_id_vanishes_at_t(link: Link) -> None:
    """Id 3 answers until its vanish time (counted from inside set_faults) and not after;
    the others go on answering."""
    before = time.monotonic()
    link.emu.set_faults(vanish={3: 0.5})
    assert link.ping(3)[1] == 0
    deadline = time.monotonic() + 5.0
    while time.monotonic() < deadline:
        result = link.ping(3)[1]
        ended = time.monotonic()
        if result != 0:
            break
    assert result == link.sdk.COMM_RX_TIMEOUT
    assert ended >= before + 0.5  # not before its time
    assert link.ping(3)[1] == link.sdk.COMM_RX_TIMEOUT  # and it stays gone
    assert link.ping(2)[1] == 0


@pytest.mark.parametrize("kind", ["overheating", "overload", "voltage"])
def test_hardware_error_flags(link: Link, kind: str) -> None:
    family = "dynamixel_x" if link.sdk is dxl else "feetech_sts"
    link.emu.set_faults(hw_error={4: kind})
    _, result, error = link.ping(4)
    reg = (X["hardware_error_status"] if link.sdk is dxl else S["status"])
    value, result, _ = link.ph.read1ByteTxRx(link.port, 4, reg.address)
    assert result == 0 and value == BIT[family][kind]
    assert error == (dxl_protocol.ERR_ALERT if link.sdk is dxl else BIT[family][kind])
    assert link.ping(3)[2] == 0  # only id 4 is faulty
    if link.sdk is scs:  # Feetech status follows the condition live
        link.emu.clear_faults()
        assert link.ping(4)[1:] == (0, 0)


def test_close_port_errors_instead_of_hanging(link: Link) -> None:
    assert link.ping(1)[1] == 0
    link.emu.set_faults(close_port=True)
    done, outcome = within(3.0, lambda: link.ping(1)[1])
    assert done, "the SDK hung after the port closed"
    assert isinstance(outcome, Exception) or outcome != 0
    assert link.emu.counters()["ping"] == 1  # the log stays readable
    link.port.is_open = False  # the fd is dead; nothing to close


def test_wrong_baud_gets_no_answer_then_the_right_one_does() -> None:
    for link in open_link("dynamixel", baud=57600):
        assert link.ping(1)[1] == dxl.COMM_RX_TIMEOUT
        assert link.emu.counters()["baud_mismatch"] == 1
        assert link.emu.log() == []
        assert link.port.setBaudRate(1_000_000)
        assert link.ping(1)[1] == 0
        link.emu.set_baud(57600)
        assert link.ping(1)[1] == dxl.COMM_RX_TIMEOUT
        assert link.port.setBaudRate(57600) and link.ping(1)[1] == 0


def test_non_standard_rate_is_seen_through_termios2() -> None:
    with Emulator("feetech", STS_ROBOT, baud=128000) as emu:
        port = scs.PortHandler(emu.port)
        ph = scs.PacketHandler(0)
        assert port.openPort()  # 1 Mbit/s
        assert ph.ping(port, 1)[1] == scs.COMM_RX_TIMEOUT
        assert port.setBaudRate(128000)
        assert ph.ping(port, 1)[1:] == (0, 0)
        port.closePort()


# ---------------------------------------------------------------------------- command


def test_biped_emulate_prints_a_pingable_port() -> None:
    exe = Path(sys.executable).parent / "biped"
    proc = subprocess.Popen([str(exe), "emulate", "--protocol", "dynamixel"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT)
    try:
        assert proc.stdout is not None
        ready, _, _ = select.select([proc.stdout], [], [], 15.0)
        assert ready, "biped emulate printed nothing"
        path = proc.stdout.readline().decode().strip()
        if not path:
            proc.wait(5.0)
            assert proc.stderr is not None
            pytest.fail(f"biped emulate exited: {proc.stderr.read().decode()[-800:]}")
        assert path.startswith("/dev/") and os.path.exists(path)
        port = dxl.PortHandler(path)
        assert port.openPort()
        assert dxl.PacketHandler(2.0).ping(port, 18)[:2] == (1060, 0)
        port.closePort()
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(10.0) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_a_starved_emulator_runs_what_the_host_sent_before_it_answers_a_test(
        link: Link) -> None:
    """A stalled emulator (SIGSTOP: a loaded machine) with goal packets waiting on the pty,
    more than one 4 kB read of them: a register read the test asks for after they were sent
    sees the last goal, not one from the middle of the backlog."""
    ids = IDS[:4]
    below = {i: near_max_limit(link, i) - 100 for i in ids}   # inside every servo's limits
    count = 350 if link.sdk is dxl else 600                   # 34 and 20 bytes a packet
    pid = link.emu.pid
    assert pid is not None
    os.kill(pid, signal.SIGSTOP)
    try:
        for k in range(count):     # sync writes of 4 servos: about 12 kB waiting (a pty
            #                           takes 20 kB before the writer blocks)
            assert sync_write(link, "goal_position", {i: below[i] + k % 100 for i in ids}) == 0
        asked: list[dict[int, int]] = []
        reader = threading.Thread(target=lambda: asked.append(
            {i: link.emu.registers(i)["goal_position"] for i in ids}), daemon=True)
        reader.start()             # its request waits on the control socket meanwhile
    finally:
        os.kill(pid, signal.SIGCONT)
    reader.join(TEST_TIMEOUT_S)
    assert asked == [{i: below[i] + (count - 1) % 100 for i in ids}]
