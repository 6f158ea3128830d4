"""The wire takes time: the driver's per-tick wire budget (robot/bus/wire_time.py) against a
hand calculation from the protocols' packet formats, a --rate the wire cannot carry
refused before anything moves, an accepted rate held on the emulator (tick counts, not
wall-clock), and the emulator's replies never faster than a real 8N1 line."""

from __future__ import annotations

import io
import json
import time
from contextlib import redirect_stdout
from pathlib import Path

import pytest
import serial
from bus_harness import TEST_TIMEOUT_MS
from waiting import sleep_until, wait_for

import robot.cli as cli
from robot.bus.dynamixel.protocol2 import DynamixelBus
from robot.bus.factory import make_bus
from robot.bus.servo_map import ServoMap
from robot.config.bundled import ROBOTS_DIR
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.loop.streamer import Streamer
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

N = 18
#: Hand calculation, [bytes] per tick part, from the manuals' packet layouts:
#: Protocol 2.0 instruction = FF FF FD 00 + id + len(2) + inst + params + CRC(2) = 10 + p;
#: status = 11 + data. Protocol 1.0 / Feetech: FF FF + id + len + inst + params + sum = 6 + p;
#: status = 6 + data. State blocks: XL430 Present Load(126)..Present Temperature(146) =
#: 21 bytes; STS Present Position(56)..Status(65) = 10; AX Present Position(36)..Present
#: Temperature(43) = 8. Goal Position: X 4 bytes, STS 2, AX 2.
HAND = {
    # sync write: 10 + addr(2) + len(2) + N*(id + 4); sync read: 10 + 4 + N ids, N * (11+21)
    "dynamixel": (10 + 4 + N * 5, 10 + 4 + N + N * (11 + 21)),
    # sync write: 6 + addr + len + N*(id + 2); sync read: 6 + 2 + N, N * (6 + 10)
    "feetech": (6 + 2 + N * 3, 6 + 2 + N + N * (6 + 10)),
    # sync write as Feetech; no sync read: N * (read 6 + 2, status 6 + 8)
    "dynamixel1": (6 + 2 + N * 3, N * ((6 + 2) + (6 + 8))),
}
ROBOT = {"dynamixel": "biped18-dynamixel", "feetech": "biped18-feetech",
         "dynamixel1": "biped18-ax12"}


def hand_max_rate(write: int, read: int, baud: int, read_every: int) -> float:
    w, r = write * 10 / baud, read * 10 / baud
    return 1 / max(w + r / read_every, (w + r) / 2)


@pytest.mark.parametrize("kind", sorted(HAND))
@pytest.mark.parametrize("baud", [57600, 1_000_000])
def test_tick_wire_matches_the_hand_calculation(kind: str, baud: int) -> None:
    robot = load_robot(ROBOTS_DIR / f"{ROBOT[kind]}.toml")
    bus = make_bus(kind, robot=robot, port="/dev/null", baud=baud)
    wire = bus.tick_wire(10)
    assert wire is not None
    write, read = HAND[kind]
    assert (wire.write_bytes, wire.read_bytes) == (write, read)
    assert wire.write_s == pytest.approx(write * 10 / baud)
    assert wire.max_rate_hz == pytest.approx(hand_max_rate(write, read, baud, 10))
    # design.md's rule of thumb for Dynamixel, writes only: 14 + 5N bytes.
    if kind == "dynamixel":
        assert wire.write_bytes == 14 + 5 * N
    assert make_bus("sim", robot=robot).tick_wire(10) is None


def test_the_bundled_robots_at_their_baud_carry_the_default_200_hz() -> None:
    for kind in HAND:
        robot = load_robot(ROBOTS_DIR / f"{ROBOT[kind]}.toml")
        wire = make_bus(kind, robot=robot, port="/dev/null").tick_wire(10)
        assert wire is not None and wire.max_rate_hz > 200, kind


def robot_toml(tmp_path: Path, baud: int) -> Path:
    text = (ROBOTS_DIR / "biped18-dynamixel.toml").read_text()
    text = text.replace("timeout_ms = 20.0", f"timeout_ms = {TEST_TIMEOUT_MS}")
    path = tmp_path / "robot.toml"
    path.write_text(text.replace("baud = 1000000", f"baud = {baud}"))
    return path


def walk(emu: Emulator, path: Path, rate: float, capsys: pytest.CaptureFixture[str],
         *more: str) -> tuple[int, str, str]:
    out = io.StringIO()
    with redirect_stdout(out):
        code = cli.main(["walk", "--bus", "dynamixel", "--port", emu.port, "--robot", str(path),
                         "--rate", str(rate), "--json", *more])
    return code, out.getvalue(), capsys.readouterr().err


def test_a_rate_the_wire_cannot_carry_is_refused_before_anything_moves(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = robot_toml(tmp_path, 57600)
    robot = load_robot(path)
    top = hand_max_rate(*HAND["dynamixel"], 57600, 10)          # 16.2 Hz
    with Emulator("dynamixel", robot, baud=57600) as emu:
        code, out, err = walk(emu, path, 200, capsys, "--seconds", "1")
        assert code == 2 and out == ""
        lines = err.strip().splitlines()
        assert len(lines) == 1, err
        assert "--rate 200: 18 servos on dynamixel at 57600 baud carry at most " \
               f"{top:.0f} Hz" in lines[0] and f"use --rate {int(top)} or less" in lines[0]
        # Nothing moved: no goal, no torque.
        assert not [p for p in emu.log() if p.instruction in ("write", "sync_write")
                    and p.address in (64, 116)]
        assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}


def test_an_accepted_rate_holds_on_the_emulator(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    path = robot_toml(tmp_path, 57600)
    robot = load_robot(path)
    with Emulator("dynamixel", robot, baud=57600) as emu:
        # 5 Hz: 200 ms a tick; a read tick's 124 ms of wire leaves room for a busy host.
        code, out, err = walk(emu, path, 5, capsys, "--seconds", "3")
        summary = json.loads(out)
        assert code == 0, err
        assert summary["overruns"] == 0, summary


class UncheckedBus(DynamixelBus):
    """The real Dynamixel bus without its rate check (to see what the wire does)."""

    def check_rate(self, rate_hz: float, *, read_every: int) -> None:
        return None


def test_the_emulators_wire_makes_200_hz_at_57600_overrun(tmp_path: Path) -> None:
    """Bypassing the check, the emulated wire itself cannot carry 18 servos' write + read
    at 200 Hz: the loop counts overruns."""
    path = robot_toml(tmp_path, 57600)
    robot = load_robot(path)
    with Emulator("dynamixel", robot, baud=57600) as emu:
        bus = UncheckedBus(emu.port, baud=57600, robot=robot, timeout_ms=500)
        bus.open()
        try:
            engine = GaitEngine(robot, load_gait("walk").params)
            stats = Streamer(ServoMap(robot), bus, engine, rate_hz=200.0).run(seconds=0.3)
        finally:
            bus.close()
        assert stats.overruns > 0
        assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}


def test_check_rate_names_the_baud(tmp_path: Path) -> None:
    from robot.bus.rate_check import check_rate

    robot = load_robot(robot_toml(tmp_path, 57600))
    bus = make_bus("dynamixel", robot=robot, port="/dev/null")
    check_rate(bus, 16.0, 10)
    with pytest.raises(ConfigError, match="at 57600 baud carry at most 16 Hz"):
        check_rate(bus, 17.0, 10)
    with pytest.raises(ConfigError, match="at 57600 baud carry at most 16 Hz"):
        bus.check_rate(17.0, read_every=10)           # the Bus interface the Streamer calls
    assert bus.max_rate_hz(read_every=10) == pytest.approx(
        hand_max_rate(*HAND["dynamixel"], 57600, 10))
    check_rate(make_bus("sim", robot=robot), 1000.0, 10)


@pytest.mark.parametrize("baud", [9600, 57600])
def test_a_reply_is_never_faster_than_the_wire(baud: int) -> None:
    """A ping (Protocol 2.0: 10-byte instruction, 14-byte status) cannot come back before
    its 24 bytes have crossed the line at 10 bits each (a lower bound, not a speed goal)."""
    robot = load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")
    with Emulator("dynamixel", robot, baud=baud) as emu:
        bus = make_bus("dynamixel", robot=robot, port=emu.port, baud=baud, timeout_ms=500,
                       check_health=False)
        bus.open()
        try:
            for _ in range(5):
                t0 = time.perf_counter()
                assert bus.ping(1) == 1060
                assert time.perf_counter() - t0 >= 24 * 10 / baud
        finally:
            bus.close(torque_off=False)


def test_flushing_the_output_before_each_packet_loses_nothing_a_uart_had_sent() -> None:
    """pypot's pattern: flush output, write a packet, the next one later. Each sync write
    of 18 goals (14 + 5 x 18 = 104 bytes) is given the time a 9600 baud UART takes to send
    it (108 ms), then the output buffer is flushed: the emulator must have taken every one."""
    robot = load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")
    baud, count = 9600, 12
    with Emulator("dynamixel", robot, baud=baud) as emu:
        port = serial.Serial(emu.port, baud, timeout=0.1)
        try:
            packet = _sync_write_goals(robot.ids, 2048)
            assert len(packet) == 14 + 5 * len(robot.ids)
            for _ in range(count):
                port.reset_output_buffer()
                port.write(packet)
                sleep_until(time.monotonic() + len(packet) * 10 / baud)
            assert wait_for(lambda: emu.counters().get("sync_write", 0) >= count, timeout_s=5)
            assert emu.counters()["sync_write"] == count
        finally:
            port.close()


def _sync_write_goals(ids: tuple[int, ...], ticks: int) -> bytes:
    """A Protocol 2.0 Sync Write of Goal Position(116, 4 bytes) = ``ticks`` to ``ids``, with
    its CRC, built from the e-Manual's packet layout and CRC-16 (polynomial 0x8005)."""
    params = (116).to_bytes(2, "little") + (4).to_bytes(2, "little") + b"".join(
        bytes([sid]) + ticks.to_bytes(4, "little") for sid in ids)
    body = bytes([0xFF, 0xFF, 0xFD, 0x00, 0xFE]) + (len(params) + 3).to_bytes(2, "little") + \
        bytes([0x83]) + params
    crc = 0
    for b in body:
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
    return body + crc.to_bytes(2, "little")
