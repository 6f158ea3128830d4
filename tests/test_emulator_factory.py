"""Factory-new servos on the emulator, driven through the real vendor SDKs.

Values from the manuals: ROBOTIS e-Manual XL430-W250 control table (ID(7) 1, Baud Rate(8)
1 = 57600, Return Delay Time(9) 250 = 500 us; EEPROM writable only with Torque Enable(64)
at 0, Access Error 7 otherwise); Feetech STS memory table (ID(5) 1, Baud Rate(6) 0 =
1 Mbps, Return Delay Time(7) 0, Lock(55) 1: EEPROM changes are not saved until it is 0).
"""

from __future__ import annotations

import faulthandler
import select
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import dynamixel_sdk as dxl
import pytest
import scservo_sdk as scs
from sdk_timeouts import allow_slow_replies

from sim.emulator.chain import Emulator, EmulatorError

ROOT = Path(__file__).resolve().parent.parent
X_ID, X_BAUD, X_DELAY, X_TORQUE = 7, 8, 9, 64
S_ID, S_BAUD, S_LOCK, S_TORQUE = 5, 6, 55, 40


@pytest.fixture(autouse=True)
def patient_sdks(monkeypatch: pytest.MonkeyPatch) -> None:
    allow_slow_replies(monkeypatch)


@pytest.fixture(autouse=True)
def watchdog() -> Iterator[None]:
    faulthandler.dump_traceback_later(30.0, exit=True)
    yield
    faulthandler.cancel_dump_traceback_later()


def dxl_port(emu: Emulator, baud: int) -> tuple[Any, Any]:
    port = dxl.PortHandler(emu.port)
    assert port.openPort() and port.setBaudRate(baud)
    return port, dxl.PacketHandler(2.0)


def test_factory_new_dynamixel_values_as_shipped() -> None:
    with Emulator.factory_new("dynamixel", 3) as emu:
        for i in range(3):
            regs = emu.registers_of(i)
            assert (regs["id"], regs["baud_rate"], regs["return_delay_time"]) == (1, 1, 250)
            assert regs["torque_enable"] == 0 and regs["present_position"] == 2048
        port, ph = dxl_port(emu, 57600)
        assert ph.ping(port, 1)[1] == dxl.COMM_RX_TIMEOUT      # nothing plugged in yet
        emu.plug(0)
        assert ph.ping(port, 1)[:3] == (1060, dxl.COMM_SUCCESS, 0)
        port.setBaudRate(1_000_000)
        assert ph.ping(port, 1)[1] == dxl.COMM_RX_TIMEOUT      # wrong baud: silence
        port.closePort()


def test_dynamixel_setup_one_at_a_time_keeps_id_and_baud() -> None:
    with Emulator.factory_new("dynamixel", 2) as emu:
        port, ph = dxl_port(emu, 57600)
        for index, new_id in enumerate((11, 12)):
            emu.plug(index)
            port.setBaudRate(57600)
            assert ph.write1ByteTxRx(port, 1, X_TORQUE, 1)[:2] == (dxl.COMM_SUCCESS, 0)
            # EEPROM is locked while torque is on: Access Error (7).
            assert ph.write1ByteTxRx(port, 1, X_ID, new_id) == (dxl.COMM_SUCCESS, 7)
            assert ph.write1ByteTxRx(port, 1, X_TORQUE, 0)[:2] == (dxl.COMM_SUCCESS, 0)
            # The reply to the id write comes from the old id; the new one answers next.
            assert ph.write1ByteTxRx(port, 1, X_ID, new_id) == (dxl.COMM_SUCCESS, 0)
            assert ph.ping(port, 1)[1] == dxl.COMM_RX_TIMEOUT
            assert ph.ping(port, new_id)[1] == dxl.COMM_SUCCESS
            # Baud 3 = 1 Mbps: the reply still goes out at 57600, then 57600 is deaf.
            assert ph.write1ByteTxRx(port, new_id, X_BAUD, 3) == (dxl.COMM_SUCCESS, 0)
            assert ph.ping(port, new_id)[1] == dxl.COMM_RX_TIMEOUT
            port.setBaudRate(1_000_000)
            assert ph.ping(port, new_id)[1] == dxl.COMM_SUCCESS
        emu.plug(None)
        assert ph.ping(port, 11)[1] == dxl.COMM_RX_TIMEOUT
        emu.plug_all()      # powered on again: EEPROM kept, torque off, return delay 250
        for new_id in (11, 12):
            value, result, _ = ph.read1ByteTxRx(port, new_id, X_DELAY)
            assert (result, value) == (dxl.COMM_SUCCESS, 250)
        assert emu.registers_of(1)["id"] == 12
        port.closePort()


def test_two_servos_with_one_id_both_execute_and_answer() -> None:
    with Emulator.factory_new("dynamixel", 2) as emu:
        emu.plug_all()
        port, ph = dxl_port(emu, 57600)
        assert ph.write1ByteTxRx(port, 1, X_DELAY, 0)[0] == dxl.COMM_SUCCESS
        assert [emu.registers_of(i)["return_delay_time"] for i in (0, 1)] == [0, 0]
        found, result = ph.broadcastPing(port)
        assert result == dxl.COMM_SUCCESS and list(found) == [1]
        port.closePort()


def test_feetech_factory_new_and_the_lock_flag() -> None:
    with Emulator.factory_new("feetech", 2) as emu:
        regs = emu.registers_of(0)
        assert (regs["id"], regs["baud_rate"], regs["return_delay_time"]) == (1, 0, 0)
        assert regs["lock"] == 1 and regs["torque_enable"] == 0
        port = scs.PortHandler(emu.port)
        assert port.openPort() and port.setBaudRate(1_000_000)
        ph = scs.PacketHandler(0)
        emu.plug(0)
        assert ph.ping(port, 1)[1:] == (scs.COMM_SUCCESS, 0)
        # Locked (factory): the id changes now but is not saved over a power cycle.
        assert ph.write1ByteTxRx(port, 1, S_ID, 5) == (scs.COMM_SUCCESS, 0)
        assert ph.ping(port, 5)[1] == scs.COMM_SUCCESS
        emu.plug(None)
        emu.plug(0)
        assert ph.ping(port, 1)[1] == scs.COMM_SUCCESS
        # Unlocked: saved.
        assert ph.write1ByteTxRx(port, 1, S_LOCK, 0) == (scs.COMM_SUCCESS, 0)
        assert ph.write1ByteTxRx(port, 1, S_ID, 6) == (scs.COMM_SUCCESS, 0)
        assert ph.write1ByteTxRx(port, 6, S_BAUD, 4) == (scs.COMM_SUCCESS, 0)  # 115200
        emu.plug(1)
        assert ph.ping(port, 1)[1] == scs.COMM_SUCCESS      # the second, still new
        emu.plug(0)
        assert ph.ping(port, 6)[1] == scs.COMM_RX_TIMEOUT
        port.setBaudRate(115200)
        assert ph.ping(port, 6)[1] == scs.COMM_SUCCESS
        assert emu.registers_of(0)["lock"] == 1             # RAM: back to its power-on value
        port.closePort()


def test_api_errors() -> None:
    with pytest.raises(EmulatorError, match="count"):
        Emulator.factory_new("dynamixel", 0)
    with pytest.raises(EmulatorError, match="protocol"):
        Emulator.factory_new("canbus", 1)
    with Emulator.factory_new("feetech", 1) as emu, pytest.raises(EmulatorError,
                                                                     match="index 1"):
        emu.plug(1)


class _Emulate:
    """``biped emulate ARGS`` in a child: its stdout lines, lines sent to its stdin."""

    def __init__(self, *args: str) -> None:
        exe = Path(sys.executable).parent / "biped"
        self.proc = subprocess.Popen([str(exe), "emulate", *args], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT)

    def line(self) -> str:
        assert self.proc.stdout is not None
        ready, _, _ = select.select([self.proc.stdout], [], [], 15.0)
        assert ready, "biped emulate printed nothing"
        return self.proc.stdout.readline().decode().strip()

    def send(self, text: str) -> str:
        """Send one stdin line; return the line it answers."""
        assert self.proc.stdin is not None
        self.proc.stdin.write(f"{text}\n".encode())
        self.proc.stdin.flush()
        return self.line()

    def stop(self) -> int:
        self.proc.send_signal(signal.SIGTERM)
        return self.proc.wait(10.0)

    def __enter__(self) -> _Emulate:
        return self

    def __exit__(self, *exc: object) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


def test_biped_emulate_factory_new_plugs_on_each_line() -> None:
    with _Emulate("--factory-new", "2", "--protocol", "dynamixel") as em:
        path = em.line()
        assert path.startswith("/dev/"), path
        port = dxl.PortHandler(path)
        assert port.openPort() and port.setBaudRate(57600)
        ph = dxl.PacketHandler(2.0)
        assert ph.ping(port, 1)[1] == dxl.COMM_RX_TIMEOUT
        for n in (1, 2):
            assert em.send("") == f"plugged new servo {n} of 2"
            assert ph.ping(port, 1)[:2] == (1060, dxl.COMM_SUCCESS)
            assert ph.write1ByteTxRx(port, 1, X_ID, 20 + n)[0] == dxl.COMM_SUCCESS
        assert em.send("all") == "plugged all 2 servos"
        found, result = ph.broadcastPing(port)
        assert result == dxl.COMM_SUCCESS and sorted(found) == [21, 22]
        port.closePort()
        assert em.stop() == 0


def test_biped_emulate_factory_new_dual_axis_cases() -> None:
    """--model 2XL430-W250: each line plugs a whole case, both axes (model number 1090,
    ids 1 and 2 from the factory: e-Manual 2XL430-W250 page)."""
    with _Emulate("--factory-new", "2", "--protocol", "dynamixel",
                  "--model", "2XL430-W250") as em:
        port = dxl.PortHandler(em.line())
        assert port.openPort() and port.setBaudRate(57600)
        ph = dxl.PacketHandler(2.0)
        for n in (1, 2):
            assert em.send("") == f"plugged new servo {n} of 2"
            found, result = ph.broadcastPing(port)
            assert result == dxl.COMM_SUCCESS
            assert {i: m for i, (m, _) in found.items()} == {1: 1090, 2: 1090}
            for axis in (1, 2):
                new = 10 * n + axis
                assert ph.write1ByteTxRx(port, axis, X_ID, new)[:2] == (dxl.COMM_SUCCESS, 0)
        assert em.send("all") == "plugged all 2 servos"
        found, result = ph.broadcastPing(port)
        assert result == dxl.COMM_SUCCESS and sorted(found) == [11, 12, 21, 22]
        port.closePort()
        assert em.stop() == 0


@pytest.mark.parametrize(("args", "named"), [
    (("--model", "2XL430-W250"), "--model"),
    (("--factory-new", "1", "--protocol", "dynamixel", "--model", "STS3215"), "model"),
])
def test_biped_emulate_model_refused_in_one_line(args: tuple[str, ...], named: str) -> None:
    with _Emulate(*args) as em:
        _, err = em.proc.communicate(timeout=30.0)
        lines = err.decode().strip().splitlines()
        assert em.proc.returncode == 2 and len(lines) == 1 and named in lines[0], lines
