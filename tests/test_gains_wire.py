"""The driver writes the robot file's gains before torque on, reads them back and verifies
them, on all three protocols, judged at the wire: the emulated servos' registers and the
packet log. Expected register values and addresses are the manuals' (written out here),
not robot/bus/tables.py.

- Dynamixel X (Protocol 2.0): Position D/I/P Gain 80/82/84, Profile Acceleration/Velocity
  108/112 (XL430-W250 e-Manual; factory D 4000, I 0, P 640).
- Protocol 1.0: AX-12A CW/CCW Compliance Margin 26/27, Slope 28/29 (factory 1/1/32/32);
  MX-28 D/I/P Gain 26/27/28 (factory 0/0/32).
- Feetech STS: P/D/I coefficient 21/22/23 in EEPROM (factory 32/32/0), Lock 55.
"""

from __future__ import annotations

import copy
import io
import json
import logging
import re
from collections.abc import Iterator
from contextlib import redirect_stdout
from pathlib import Path
from typing import Any

import pytest
from bus_harness import TEST_TIMEOUT_MS

import robot.cli as cli
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot import RobotConfig
from robot.config.robot_file import parse_robot
from robot.config.toml_io import read_toml
from robot.errors import BusError
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

#: Gain register addresses, from the manuals.
ADDRESS = {"position_d_gain": 80, "position_i_gain": 82, "position_p_gain": 84,
           "profile_acceleration": 108, "profile_velocity": 112,
           "cw_compliance_margin": 26, "ccw_compliance_margin": 27,
           "cw_compliance_slope": 28, "ccw_compliance_slope": 29,
           "d_gain": 26, "i_gain": 27, "p_gain": 28,
           "p_coefficient": 21, "d_coefficient": 22, "i_coefficient": 23}
STS_LOCK = 55
TORQUE_ENABLE = {"dynamixel": 64, "dynamixel1": 24, "feetech": 40}
ROBOT_FILE = {"dynamixel": "biped18-dynamixel", "dynamixel1": "biped18-ax12",
              "feetech": "biped18-feetech"}


def bundled_text(protocol: str) -> str:
    """The bundled robot file for ``protocol`` without its own [bus.gains] (the gains the
    robot walks with, docs/servos.md): these tests start from the factory values."""
    text = (ROBOTS_DIR / f"{ROBOT_FILE[protocol]}.toml").read_text()
    return re.sub(r"\n\[bus\.gains\][^\[]*", "\n", text, count=1)


def robot_with(protocol: str, *, bus: dict[str, int] | None = None,
               joints: dict[str, dict[str, Any]] | None = None) -> RobotConfig:
    data = copy.deepcopy(read_toml(ROBOTS_DIR / f"{ROBOT_FILE[protocol]}.toml"))
    data["bus"].pop("gains", None)      # start from the factory values (bundled_text)
    data["bus"]["timeout_ms"] = TEST_TIMEOUT_MS
    if bus:
        data["bus"]["gains"] = bus
    for name, fields in (joints or {}).items():
        data["joints"][name].update(fields)
    return parse_robot(data, source=f"{protocol}-gains.toml")


def writes_at(emu: Emulator, address: int, sid: int | None = None) -> list[int]:
    """Values written at ``address`` (write or sync write), for ``sid`` or any servo."""
    out = []
    for p in emu.log():
        if p.address == address and p.instruction in ("write", "sync_write"):
            out += [v for i, v in p.values.items() if sid is None or i == sid]
    return out


def index_of_first(emu: Emulator, address: int) -> int:
    return next(k for k, p in enumerate(emu.log()) if p.address == address
                and p.instruction in ("write", "sync_write") and 1 in p.values.values())


@pytest.fixture
def emulate() -> Iterator[Any]:
    started: list[Emulator] = []

    def start(protocol: str, robot: RobotConfig) -> Emulator:
        emu = Emulator(protocol, robot, seed=1)
        emu.start()
        started.append(emu)
        return emu

    yield start
    for emu in started:
        emu.stop()


def test_dynamixel_x_gains_are_written_before_torque_on(emulate: Any, bus_factory: Any) -> None:
    robot = robot_with("dynamixel", bus={"position_p_gain": 400, "profile_velocity": 60},
                       joints={"r_knee": {"gains": {"position_p_gain": 900,
                                                    "position_d_gain": 100}}})
    emu = emulate("dynamixel", robot)
    knee = robot.joint("r_knee").servo_id
    hip = robot.joint("r_hip_pitch").servo_id
    assert emu.registers(hip)["position_p_gain"] == 640          # the manual's factory value
    bus = bus_factory(emu, robot)
    bus.set_torque(robot.ids, enabled=True)
    for sid in robot.ids:
        r = emu.registers(sid)
        d, p = (100, 900) if sid == knee else (4000, 400)
        assert (r["position_d_gain"], r["position_i_gain"], r["position_p_gain"]) == (d, 0, p)
        assert (r["profile_acceleration"], r["profile_velocity"]) == (0, 60)
        assert r["torque_enable"] == 1
    # Every gain packet went out before the first torque-on packet.
    first_torque = index_of_first(emu, TORQUE_ENABLE["dynamixel"])
    gain_packets = [k for k, p in enumerate(emu.log()) if p.address in (80, 82, 84, 108, 112)
                    and p.instruction == "sync_write"]
    assert gain_packets and max(gain_packets) < first_torque
    assert writes_at(emu, ADDRESS["position_p_gain"], knee) == [900]
    assert bus.read_gains(knee) == {"position_d_gain": 100, "position_i_gain": 0,
                                    "position_p_gain": 900, "profile_acceleration": 0,
                                    "profile_velocity": 60}
    # A second torque-on within the same connection does not write them again.
    bus.set_torque(robot.ids, enabled=False)
    bus.set_torque(robot.ids, enabled=True)
    assert writes_at(emu, ADDRESS["position_p_gain"], knee) == [900]
    bus.close()


def test_protocol_1_ax_compliance_and_mx_pid_on_one_bus(emulate: Any,
                                                         bus_factory: Any) -> None:
    robot = robot_with("dynamixel1",
                       joints={"r_knee": {"model": "MX-28", "zero_ticks": 2048,
                                          "gains": {"p_gain": 20, "d_gain": 4}},
                               "l_knee": {"gains": {"ccw_compliance_margin": 3}}})
    emu = emulate("dynamixel1", robot)
    r_knee, l_knee = robot.joint("r_knee").servo_id, robot.joint("l_knee").servo_id
    assert emu.registers(r_knee)["p_gain"] == 32        # MX-28 e-Manual factory value
    bus = bus_factory(emu, robot)
    bus.set_torque(robot.ids, enabled=True)
    mx = emu.registers(r_knee)
    assert (mx["d_gain"], mx["i_gain"], mx["p_gain"], mx["torque_enable"]) == (4, 0, 20, 1)
    ax = emu.registers(l_knee)
    assert (ax["cw_compliance_margin"], ax["ccw_compliance_margin"], ax["cw_compliance_slope"],
            ax["ccw_compliance_slope"], ax["torque_enable"]) == (1, 3, 32, 32, 1)
    # The MX got D/I/P at 26-28, never the AX's compliance values there.
    assert writes_at(emu, 28, r_knee) == [20] and writes_at(emu, 28, l_knee) == [32]
    bus.close()


def sts_run(bus_factory: Any, emu: Emulator, robot: RobotConfig) -> None:
    bus = bus_factory(emu, robot)
    bus.set_torque(robot.ids, enabled=True)
    bus.close()


def test_sts_eeprom_gains_are_written_once_over_two_runs(emulate: Any, bus_factory: Any,
                                                        caplog: pytest.LogCaptureFixture) -> None:
    robot = robot_with("feetech", joints={"r_knee": {"gains": {"p_coefficient": 16}}})
    emu = emulate("feetech", robot)
    knee = robot.joint("r_knee").servo_id
    with caplog.at_level(logging.INFO, logger="robot.bus.sdk.gain_writer"):
        sts_run(bus_factory, emu, robot)
    assert any("EEPROM gains changed (p_coefficient 32 -> 16)" in r.getMessage()
               for r in caplog.records)
    sts_run(bus_factory, emu, robot)
    # One EEPROM write over two runs, for the one servo and the one value that differ.
    assert writes_at(emu, ADDRESS["p_coefficient"]) == [16]
    assert writes_at(emu, ADDRESS["d_coefficient"]) == []
    assert writes_at(emu, ADDRESS["i_coefficient"]) == []
    # Unlocked for the write and locked again, on that servo only (manual: Lock 0 saves).
    assert writes_at(emu, STS_LOCK) == [0, 1]
    assert writes_at(emu, STS_LOCK, knee) == [0, 1]
    # Saved: it survives a power cycle.
    emu.plug(None)
    emu.plug_all()
    assert emu.registers(knee)["p_coefficient"] == 16
    assert emu.registers(knee)["lock"] == 1
    # A changed file writes the new value, once.
    robot2 = robot_with("feetech", joints={"r_knee": {"gains": {"p_coefficient": 20}}})
    sts_run(bus_factory, emu, robot2)
    sts_run(bus_factory, emu, robot2)
    assert writes_at(emu, ADDRESS["p_coefficient"]) == [16, 20]


@pytest.mark.parametrize("protocol", ["dynamixel", "dynamixel1", "feetech"])
def test_a_read_back_mismatch_is_a_fault_naming_servo_register_and_values(
        emulate: Any, bus_factory: Any, protocol: str) -> None:
    name, value, factory = {"dynamixel": ("position_p_gain", 900, 640),
                            "dynamixel1": ("cw_compliance_slope", 64, 32),
                            "feetech": ("p_coefficient", 16, 32)}[protocol]
    robot = robot_with(protocol, joints={"l_knee": {"gains": {name: value}}})
    emu = emulate(protocol, robot)
    sid = robot.joint("l_knee").servo_id
    emu.set_faults(frozen={sid: [name]})
    bus = bus_factory(emu, robot)
    with pytest.raises(BusError) as e:
        bus.set_torque(robot.ids, enabled=True)
    msg = str(e.value)
    assert f"id {sid} (l_knee)" in msg
    assert f"{name} (address {ADDRESS[name]}) wanted {value}, read {factory}" in msg
    assert "\n" not in msg
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}
    bus.close()
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}


def test_a_walk_with_a_gain_the_servo_refuses_ends_in_a_fault_with_torque_off(
        emulate: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = bundled_text("dynamixel")
    text = text.replace("timeout_ms = 20.0", f"timeout_ms = {TEST_TIMEOUT_MS}")
    text = text.replace("[geometry]", "[bus.gains]\nposition_p_gain = 500\n\n[geometry]", 1)
    path = tmp_path / "robot.toml"
    path.write_text(text)
    robot = robot_with("dynamixel", bus={"position_p_gain": 500})
    emu = emulate("dynamixel", robot)
    victim = robot.joint("r_ankle_roll").servo_id
    emu.set_faults(frozen={victim: ["position_p_gain"]})
    out = io.StringIO()
    with redirect_stdout(out):
        code = cli.main(["walk", "--bus", "dynamixel", "--port", emu.port, "--robot", str(path),
                         "--seconds", "1", "--json"])
    summary = json.loads(out.getvalue())
    assert code == 1
    reason = json.dumps(summary)
    assert f"id {victim} (r_ankle_roll)" in reason and "wanted 500, read 640" in reason
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}
    # Nothing moved: no goal beyond the first (goal := present) was sent.
    goals = [p for p in emu.log() if p.instruction == "sync_write" and p.address == 116]
    assert len(goals) <= 1


def robot_file(tmp_path: Path, protocol: str, extra: str = "") -> Path:
    """The bundled robot for ``protocol`` with a test reply timeout and ``extra`` TOML put
    before its [geometry] table."""
    text = bundled_text(protocol)
    text = text.replace("timeout_ms = 20.0", f"timeout_ms = {TEST_TIMEOUT_MS}")
    path = tmp_path / "robot.toml"
    path.write_text(text.replace("[geometry]", f"{extra}\n[geometry]", 1))
    return path


@pytest.mark.parametrize("protocol", ["dynamixel", "dynamixel1", "feetech"])
def test_scan_and_monitor_show_each_servos_gains(emulate: Any, bus_factory: Any, tmp_path: Path,
                                                 protocol: str,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    factory = {"dynamixel": {"position_d_gain": 4000, "position_i_gain": 0,
                             "position_p_gain": 640, "profile_acceleration": 0,
                             "profile_velocity": 0},
               "dynamixel1": {"cw_compliance_margin": 1, "ccw_compliance_margin": 1,
                              "cw_compliance_slope": 32, "ccw_compliance_slope": 32},
               "feetech": {"p_coefficient": 32, "d_coefficient": 32, "i_coefficient": 0}}
    robot = robot_with(protocol)
    emu = emulate(protocol, robot)
    first, name = robot.ids[0], next(iter(factory[protocol]))
    emu.set_register(first, name, factory[protocol][name] + 1)
    path = robot_file(tmp_path, protocol)
    bus_args = ["--bus", protocol, "--port", emu.port, "--robot", str(path)]
    assert cli.main(["scan", *bus_args, "--json"]) == 0
    rows = {r["id"]: r["gains"] for r in json.loads(capsys.readouterr().out)}
    assert rows[first] == {**factory[protocol], name: factory[protocol][name] + 1}
    assert all(rows[i] == factory[protocol] for i in robot.ids[1:])
    assert cli.main(["scan", *bus_args]) == 0
    text = capsys.readouterr().out
    assert f"{name}={factory[protocol][name] + 1}" in text and f": id {first}\n" in text
    assert cli.main(["monitor", *bus_args, "--once", "--json"]) == 0
    frame = json.loads(capsys.readouterr().out.splitlines()[0])
    joints = {j["id"]: j["gains"] for j in frame["joints"]}
    assert joints[first][name] == factory[protocol][name] + 1
    assert joints[robot.ids[1]] == factory[protocol]
    # Neither wrote a gain register.
    assert not [p for p in emu.log() if p.instruction in ("write", "sync_write")
                and p.address in {ADDRESS[g] for g in factory[protocol]}]
