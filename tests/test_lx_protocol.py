"""The LX protocol's facts, from the manual written out here (LewanSoul "Bus Servo
Communication Protocol": Table 2 command list, Table 4 read answers, 3. Command packet),
against the driver's table (robot/bus/tables.py), the emulator's own transcription
(sim/emulator/lx_commands.py) and the packet codec; and the wire budget by hand."""

from __future__ import annotations

from pathlib import Path

import pytest

from robot.bus.lx import packet as lx_packet
from robot.bus.lx import wire as lx_wire
from robot.bus.lx.tables import LX_ALARM_BITS, LX_BROADCAST_ID, LX_COMMANDS
from robot.bus.tables import ERROR_BITS
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.servo.models import MODELS
from sim.emulator import lx_commands as emulator
from sim.emulator import lx_protocol

# The manual, Table 2 (command value, length of the host's packet) and Table 4 (length
# of the answer, read commands only).
MANUAL: dict[str, tuple[int, int, int | None]] = {
    "SERVO_MOVE_TIME_WRITE": (1, 7, None), "SERVO_MOVE_TIME_READ": (2, 3, 7),
    "SERVO_MOVE_TIME_WAIT_WRITE": (7, 7, None), "SERVO_MOVE_TIME_WAIT_READ": (8, 3, 7),
    "SERVO_MOVE_START": (11, 3, None), "SERVO_MOVE_STOP": (12, 3, None),
    "SERVO_ID_WRITE": (13, 4, None), "SERVO_ID_READ": (14, 3, 4),
    "SERVO_ANGLE_OFFSET_ADJUST": (17, 4, None), "SERVO_ANGLE_OFFSET_WRITE": (18, 3, None),
    "SERVO_ANGLE_OFFSET_READ": (19, 3, 4), "SERVO_ANGLE_LIMIT_WRITE": (20, 7, None),
    "SERVO_ANGLE_LIMIT_READ": (21, 3, 7), "SERVO_VIN_LIMIT_WRITE": (22, 7, None),
    "SERVO_VIN_LIMIT_READ": (23, 3, 7), "SERVO_TEMP_MAX_LIMIT_WRITE": (24, 4, None),
    "SERVO_TEMP_MAX_LIMIT_READ": (25, 3, 4), "SERVO_TEMP_READ": (26, 3, 4),
    "SERVO_VIN_READ": (27, 3, 5), "SERVO_POS_READ": (28, 3, 5),
    "SERVO_OR_MOTOR_MODE_WRITE": (29, 7, None), "SERVO_OR_MOTOR_MODE_READ": (30, 3, 7),
    "SERVO_LOAD_OR_UNLOAD_WRITE": (31, 4, None), "SERVO_LOAD_OR_UNLOAD_READ": (32, 3, 4),
    "SERVO_LED_CTRL_WRITE": (33, 4, None), "SERVO_LED_CTRL_READ": (34, 3, 4),
    "SERVO_LED_ERROR_WRITE": (35, 4, None), "SERVO_LED_ERROR_READ": (36, 3, 4),
}


def test_the_drivers_commands_are_the_manuals() -> None:
    ours = {f"SERVO_{n.upper()}": (c.code, c.params + 3, None if c.reply is None else
                                   c.reply + 3) for n, c in LX_COMMANDS.items()}
    assert ours == MANUAL


def test_the_emulators_commands_are_the_manuals() -> None:
    assert {name: (n, req, ans) for n, (name, req, ans) in emulator.COMMANDS.items()} == MANUAL


def test_alarm_bits_are_table_3() -> None:
    # Table 3: 1 over temperature, 2 over voltage, 4 locked rotor (7 = all three).
    assert {1 << b: n for b, n in LX_ALARM_BITS.items()} == {1: "overheating", 2: "voltage",
                                                             4: "overload"}
    assert ERROR_BITS["lx"] == LX_ALARM_BITS == emulator.ALARM_BITS


def test_a_move_packet_by_hand() -> None:
    # Servo 1 to position 500 (0x01F4) in 1000 ms (0x03E8): length 7, command 1;
    # 1 + 7 + 1 + 0xF4 + 0x01 + 0xE8 + 0x03 = 489 = 0x1E9, ~0xE9 & 0xFF = 0x16.
    packet = lx_packet.encode(1, "move_time_write", lx_packet.word(500) + lx_packet.word(1000))
    assert packet == bytes.fromhex("5555 01 07 01 F4 01 E8 03 16")
    assert lx_protocol.packet(1, 1, bytes.fromhex("F401E803")) == packet


def test_broadcast_id_read_by_hand() -> None:
    # 254 + 3 + 14 = 271 = 0x10F, ~0x0F & 0xFF = 0xF0
    assert lx_packet.encode(LX_BROADCAST_ID, "id_read") == bytes.fromhex("5555 FE 03 0E F0")


def test_the_reply_parser_skips_noise_echo_and_bad_checksums() -> None:
    answer = lx_protocol.packet(3, 28, (-7 & 0xFFFF).to_bytes(2, "little"))
    echo = lx_packet.encode(3, "pos_read")
    bad = answer[:-1] + bytes([answer[-1] ^ 0xFF])
    parser = lx_packet.ReplyParser()
    frames = parser.feed(b"\x00\x55" + echo + bad + answer[:4])
    frames += parser.feed(answer[4:])
    assert [(f.servo_id, f.code, len(f.params)) for f in frames] == [(3, 28, 0), (3, 28, 2)]
    assert lx_packet.value(frames[1].params, 0, 2, signed=True) == -7
    assert parser.bad_checksum == 1


def test_encode_refuses_a_wrong_parameter_count() -> None:
    with pytest.raises(ValueError, match="takes 4 parameter bytes"):
        lx_packet.encode(1, "move_time_write", b"\x00")


def test_models_step_0_24_degrees() -> None:
    for name in ("LX-16A", "LX-224", "LX-224HV"):
        m = MODELS[name]
        assert m.family == "lx" and m.resolution == 1001
        assert 1 / m.ticks_per_rad == pytest.approx(0.24 * 3.141592653589793 / 180, rel=1e-12)
    # LX-16A spec sheet: 17 kg cm at 7.4 V, 0.16 s per 60 deg, 52 g.
    assert MODELS["LX-16A"].stall_torque == pytest.approx(1.667, abs=1e-3)
    assert MODELS["LX-16A"].no_load_speed == pytest.approx(6.545, abs=1e-3)


def test_wire_budget_by_hand() -> None:
    # 10 bits a byte at 115200: 86.8 us. A move packet is 10 bytes: 0.868 ms per servo.
    assert lx_wire.write_s(18) == pytest.approx(18 * 10 * 10 / 115200)   # 15.6 ms
    # read-back: (18 + 1) x (6-byte request + 8-byte answer + 0.5 ms turnaround)
    assert lx_wire.read_s(18) == pytest.approx(19 * (14 * 10 / 115200 + 0.0005))
    top = lx_wire.max_rate_hz(18, read_every=10)
    assert top == pytest.approx(1 / (0.015625 + 0.0325894 / 10), rel=1e-4)   # ~53 Hz
    lx_wire.check_rate(50.0, 18, read_every=10)
    with pytest.raises(ConfigError, match=r"--rate 200: 18 LX servos .* use --rate 52"):
        lx_wire.check_rate(200.0, 18, read_every=10)
    assert lx_wire.max_rate_hz(12, read_every=10) > 75


def test_an_lx_robot_file_with_gains_is_refused_in_one_line(tmp_path: Path) -> None:
    text = (ROBOTS_DIR / "biped18-lx.toml").read_text()
    path = tmp_path / "lx-gains.toml"
    path.write_text(text.replace("[bus]\n", "[bus.gains]\np_gain = 3\n\n[bus]\n", 1))
    with pytest.raises(ConfigError, match=r"bus.gains.p_gain: not a gain of LX-16A .*valid: "
                                          r"none \(its firmware takes no gains"):
        load_robot(path)
