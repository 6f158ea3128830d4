"""Dynamixel Protocol 1.0 (AX-12A, AX-18A, MX-28): models, bus, emulator.

Expected addresses and values are the ROBOTIS e-Manual's (AX-12A control table,
https://emanual.robotis.com/docs/en/dxl/ax/ax-12a/), written here, not read from
robot/bus/tables.py.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from pathlib import Path

import pytest
from bus_harness import patient_copy
from sdk_timeouts import allow_slow_replies

from robot.bus.tables import TABLES
from robot.servo.models import MODELS
from sim.emulator.chain import Emulator

# e-Manual AX-12A: (address, size)
MANUAL = {"id": (3, 1), "baud_rate": (4, 1), "return_delay_time": (5, 1),
          "cw_angle_limit": (6, 2), "ccw_angle_limit": (8, 2), "torque_enable": (24, 1),
          "led": (25, 1), "goal_position": (30, 2), "moving_speed": (32, 2),
          "present_position": (36, 2), "present_speed": (38, 2), "present_load": (40, 2),
          "present_voltage": (42, 1), "present_temperature": (43, 1), "moving": (46, 1),
          "lock": (47, 1)}


def test_the_driver_table_is_the_manuals() -> None:
    table = TABLES["dynamixel_p1"]
    for name, (address, size) in MANUAL.items():
        assert (table[name].address, table[name].size) == (address, size), name


def test_ax_ticks_span_300_degrees() -> None:
    ax = MODELS["AX-12A"]
    assert (ax.number, ax.resolution, ax.family) == (12, 1024, "dynamixel_p1")
    assert ax.ticks_per_rad * 2 * math.pi == 1228.8
    assert ax.ticks_per_rad * math.radians(300) == 1024
    assert MODELS["AX-18A"].number == 18
    mx = MODELS["MX-28"]
    assert (mx.number, mx.resolution) == (29, 4096)
    assert mx.ticks_per_rad * 2 * math.pi == 4096


def test_the_protocol1_bus_uses_packet_handler_1_0() -> None:
    from robot.bus.dynamixel.protocol1 import Dynamixel1Bus

    bus = Dynamixel1Bus("/dev/null", baud=1_000_000)
    assert (bus.kind, bus.family) == ("dynamixel1", "dynamixel_p1")
    assert bus._make_packet_handler().getProtocolVersion() == 1.0


# ---------------------------------------------------------------------- the emulator
def test_the_emulator_answers_the_sdk_in_protocol_1(monkeypatch: pytest.MonkeyPatch) -> None:
    import dynamixel_sdk as sdk

    allow_slow_replies(monkeypatch)   # the SDK's 34 ms reply window: a busy machine misses it

    from sim.emulator.chain import Emulator

    with Emulator("dynamixel1", ids=[1, 2]) as emu:
        port = sdk.PortHandler(emu.port)
        ph = sdk.PacketHandler(1.0)
        assert port.openPort() and port.setBaudRate(1_000_000)
        try:
            assert ph.ping(port, 1) == (12, sdk.COMM_SUCCESS, 0)       # AX-12A model 12
            assert ph.ping(port, 7)[1] == sdk.COMM_RX_TIMEOUT
            assert ph.read2ByteTxRx(port, 2, 36)[0] == 512              # Present Position
            assert ph.read2ByteTxRx(port, 2, 8)[0] == 1023              # CCW Angle Limit
            assert ph.write1ByteTxRx(port, 1, 24, 1) == (sdk.COMM_SUCCESS, 0)
            # Goal Position(30) above CCW Angle Limit: Angle Limit Error (bit 1)
            assert ph.write2ByteTxRx(port, 1, 30, 1024)[1] == 1 << 1
            # Present Position is read-only: Range Error (bit 3)
            assert ph.write2ByteTxRx(port, 1, 36, 100)[1] == 1 << 3
        finally:
            port.closePort()
        writes = [p for p in emu.log() if p.instruction == "write"]
        assert [(p.address, p.values) for p in writes][0] == (24, {1: 1})
        assert emu.registers(1)["torque_enable"] == 1


# ---------------------------------------------------------------------- the kit's robot
def test_the_ax12_humanoid_loads_inside_the_ax_range() -> None:
    from robot.bus.servo_map import ServoMap
    from robot.config.bundled import ROBOTS_DIR
    from robot.config.robot_file import load_robot

    robot = load_robot(ROBOTS_DIR / "biped18-ax12.toml")
    assert (robot.bus.kind, robot.bus.model, robot.bus.baud) == ("dynamixel1", "AX-12A",
                                                                  1_000_000)
    assert len(robot.joints) == 18
    sm = ServoMap(robot)
    assert sm.tick_min.min() >= 0 and sm.tick_max.max() <= 1023
    # 1 rad is 1024 / (300 deg in rad) = 195.6 ticks from the centre 512
    assert sm.goals(sm.vector({"r_knee": 1.0}).tolist())[4] == round(512 + 1024 / math.radians(300))


def test_the_ax12_humanoid_walks_10s_in_mujoco(capsys: pytest.CaptureFixture[str]) -> None:
    from robot.cli import main

    assert main(["walk", "--json", "--robot", "biped18-ax12", "--seconds", "10"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["fell"] is False and r["distance_m"] > 0.3


# ---------------------------------------------------------------------- CLI on the wire
AX_TOML = "biped18-ax12"
TORQUE_ENABLE, GOAL_POSITION = 24, 30      # e-Manual AX-12A addresses


@pytest.fixture
def ax_emu() -> Iterator[Emulator]:
    from robot.config.bundled import ROBOTS_DIR
    from robot.config.robot_file import load_robot

    with Emulator("dynamixel1", load_robot(ROBOTS_DIR / f"{AX_TOML}.toml")) as emu:
        yield emu


@pytest.fixture
def ax_bus(ax_emu: Emulator, tmp_path: Path) -> list[str]:
    """The command-line bus options for ``ax_emu``: the AX robot with a reply timeout a
    busy test machine keeps."""
    toml = patient_copy(AX_TOML, tmp_path / f"{AX_TOML}.toml")
    return ["--bus", "dynamixel1", "--port", ax_emu.port, "--robot", str(toml)]


def test_scan_finds_18_ax12(ax_emu: Emulator, ax_bus: list[str],
                            capsys: pytest.CaptureFixture[str]) -> None:
    from robot.cli import main

    assert main(["scan", *ax_bus, "--ids", "1-20", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["id"] for r in rows] == list(range(1, 19))
    assert {r["model"] for r in rows} == {12}                   # AX-12A
    assert rows[6]["joint"] == "l_hip_yaw"
    assert {p.instruction for p in ax_emu.log()} <= {"ping", "read", "write", "sync_write"}


def test_torque_on_then_off_at_address_24(ax_emu: Emulator, ax_bus: list[str]) -> None:
    from robot.cli import main

    ax_emu.log(clear=True)
    assert main(["torque", "on", *ax_bus]) == 0
    assert {ax_emu.registers(i)["torque_enable"] for i in range(1, 19)} == {1}
    on = [p for p in ax_emu.log() if p.address == TORQUE_ENABLE and p.instruction == "write"]
    assert sorted(i for p in on for i in p.ids) == list(range(1, 19))
    assert main(["torque", "off", *ax_bus]) == 0
    assert {ax_emu.registers(i)["torque_enable"] for i in range(1, 19)} == {0}


def test_pose_rest_sync_writes_goals_inside_0_1023(ax_emu: Emulator,
                                                    ax_bus: list[str]) -> None:
    from robot.cli import main

    ax_emu.log(clear=True)
    assert main(["pose", "rest", *ax_bus, "--speed", "5"]) == 0
    goals = [p for p in ax_emu.log() if p.instruction == "sync_write"
             and p.address == GOAL_POSITION]
    assert goals and all(p.length == 2 for p in goals)
    last = goals[-1].values
    assert all(0 <= v <= 1023 for v in last.values())
    # rest knee 1.1 rad: 512 + 1.1 * 1024 / (300 deg) ticks on ids 4 and 10 (sign +1)
    knee = round(512 + 1.1 * 1024 / math.radians(300))
    assert last[4] == knee and last[10] == knee
    # no sync read on the AX: state is read servo by servo
    assert not any(p.instruction.endswith("sync_read") for p in ax_emu.log())


def test_a_short_walk_on_the_emulated_chain(ax_emu: Emulator, ax_bus: list[str],
                                            capsys: pytest.CaptureFixture[str]) -> None:
    from robot.cli import main

    ax_emu.log(clear=True)
    code = main(["walk", *ax_bus, "--seconds", "1", "--rate", "50", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0 and out["bus_errors"] == 0, out
    writes = [p for p in ax_emu.log() if p.instruction == "sync_write"
              and p.address == GOAL_POSITION]
    assert len(writes) >= 40 and all(len(p.ids) == 18 for p in writes)


def test_a_missing_servo_is_one_line_naming_its_joint(
        ax_emu: Emulator, ax_bus: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    from robot.cli import main

    ax_emu.set_faults(missing_ids=[10])
    assert main(["torque", "on", *ax_bus]) != 0
    err = capsys.readouterr().err.strip()
    assert "id 10 (l_knee)" in err and len(err.splitlines()) == 1, err


def test_setup_motors_gives_a_factory_new_ax12_its_joint_id(
        capsys: pytest.CaptureFixture[str]) -> None:
    from robot.cli import main

    with Emulator.factory_new("dynamixel1", 1) as emu:
        emu.plug(0)
        assert emu.registers_of(0)["return_delay_time"] == 250      # e-Manual: 500 us
        assert main(["setup-motors", "--robot", AX_TOML, "--bus", "dynamixel1", "--port",
                     emu.port, "--joint", "r_knee", "--yes"]) == 0
        assert "r_knee: id 4 at 1000000 baud" in capsys.readouterr().out
        regs = emu.registers_of(0)
        assert (regs["id"], regs["baud_rate"], regs["return_delay_time"]) == (4, 1, 0)
        assert regs["lock"] == 0      # AX Lock(47) = 1 would lock the EEPROM: never written


def test_calibrate_zero_on_the_ax12_writes_no_goal(ax_emu: Emulator, ax_bus: list[str],
                                                   tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    from robot.cli import main
    from robot.config.robot_file import load_robot

    for sid in range(1, 19):        # the user holds the robot in its zero pose
        ax_emu.set_register(sid, "goal_position", 500 + sid)
        ax_emu.set_register(sid, "present_position", 500 + sid)
    ax_emu.log(clear=True)
    out = tmp_path / "ax.toml"
    assert main(["calibrate", *ax_bus, "--out", str(out), "--zero", "--yes"]) == 0
    assert f"wrote {out}" in capsys.readouterr().out
    new = load_robot(out)
    assert new.joint("r_knee").zero_ticks == 504 and new.joint("l_elbow").zero_ticks == 518
    assert not [p for p in ax_emu.log() if p.address == GOAL_POSITION]
    assert {ax_emu.registers(i)["torque_enable"] for i in range(1, 19)} == {0}
