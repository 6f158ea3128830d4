"""Every protocol variant and table layout issue 21 adds, at the wire: ``biped scan`` names
the servos, ``calibrate --zero`` reads their zero without moving them, ``walk`` streams
goals to them (at the address and width their manual prints, inside the joint limits)
and leaves them torque-off, ``setup-motors`` gives a factory-new one its joint's id, the
robot's baud and return delay 0 (a dual-axis case both ids at once). One robot per table
layout (tests/zoo_robots.py), not per model; every model is named by a scan below.

Expected values come from the manuals (goal addresses, factory ids and bauds written out
here and in zoo_robots), never from the driver's tables.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import pytest
from sdk_timeouts import allow_slow_replies
from zoo_robots import DUAL_CASES, DUAL_MODEL, VARIANTS, Variant, robot_file

from robot.bus.servo_map import ServoMap
from robot.cli import main
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from sim.emulator.chain import Emulator
from sim.emulator.servo import ServoSpec
from sim.emulator.servo_models import MODELS, PROTOCOL_FAMILIES

pytest_plugins = ("bus_harness",)


@pytest.fixture(autouse=True)
def patient_sdks(monkeypatch: pytest.MonkeyPatch) -> None:
    allow_slow_replies(monkeypatch)


@pytest.fixture(params=sorted(VARIANTS))
def variant(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[tuple[Variant, Path]]:
    v = VARIANTS[request.param]
    yield v, robot_file(v, tmp_path, f"zoo-{request.param.replace('_', '-')}")


def _bus(emu: Emulator, toml: Path) -> list[str]:
    return ["--bus", emu.protocol, "--port", emu.port, "--robot", str(toml)]


def _model_of(robot: RobotConfig, sid: int) -> str:
    joint = robot.joint_by_id(sid)
    assert joint is not None
    return robot.servo(joint).name


def test_scan_calibrate_walk(variant: tuple[Variant, Path],
                             capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    v, toml = variant
    robot = load_robot(toml)
    with Emulator(v.protocol, robot) as emu:
        # scan: every joint answers and is named its model
        assert main(["scan", *_bus(emu, toml), "--ids", "1-20", "--json"]) == 0
        rows = json.loads(capsys.readouterr().out)
        assert [r["id"] for r in rows] == sorted(robot.ids)
        assert {r["id"]: r["model_name"] for r in rows} == {
            sid: _model_of(robot, sid) for sid in robot.ids}
        if v.dual:
            cases = {r["joint"]: r["case"] for r in rows if r["case"]}
            assert cases == {j: c for c, js in DUAL_CASES.items() for j in js}
        # calibrate --zero: the pose held by hand becomes zero_ticks; nothing moves
        for i, sid in enumerate(robot.ids):
            zero = robot.joints[i].zero_ticks + sid
            emu.set_register(sid, "goal_position", zero)
            emu.set_register(sid, "present_position", zero)
        emu.log(clear=True)
        out = tmp_path / "calibrated.toml"
        assert main(["calibrate", *_bus(emu, toml), "--out", str(out), "--zero",
                     "--yes"]) == 0, capsys.readouterr().err
        capsys.readouterr()
        calibrated = load_robot(out)
        assert [j.zero_ticks for j in calibrated.joints] == [
            j.zero_ticks + j.servo_id for j in robot.joints]
        assert not [p for p in emu.log() if p.address == v.goal[0]]
        # walk: goals at the manual's Goal Position, inside the limits; torque off after
        emu.log(clear=True)
        code = main(["walk", *_bus(emu, toml), "--seconds", "1", "--rate", "50", "--json"])
        result = json.loads(capsys.readouterr().out)
        assert code == 0 and result["bus_errors"] == 0, result
        goals = [p for p in emu.log() if p.instruction == "sync_write" and
                 p.address == v.goal[0]]
        assert len(goals) >= 40 and {p.length for p in goals} == {v.goal[1]}
        sm = ServoMap(robot)
        lo = dict(zip(sm.ids, sm.tick_min.tolist(), strict=True))
        hi = dict(zip(sm.ids, sm.tick_max.tolist(), strict=True))
        assert all(lo[sid] <= t <= hi[sid] for p in goals for sid, t in p.values.items())
        assert {emu.registers(sid)["torque_enable"] for sid in robot.ids} == {0}


#: The rate each model ships at (its manual's initial Baud Rate).
FACTORY_BAUD = {"XL-320": 1_000_000, "SCS0009": 1_000_000, "XM430-W350": 57_600,
                "XL330-M288": 57_600, "MX-28(2.0)": 57_600, "MX-28": 57_600, "MX-64": 57_600,
                "MX-106": 57_600, DUAL_MODEL: 57_600}


def test_setup_motors_on_a_factory_new_servo(variant: tuple[Variant, Path],
                                             capsys: pytest.CaptureFixture[str]) -> None:
    v, toml = variant
    robot = load_robot(toml)
    joint = robot.joint("r_hip_pitch" if v.dual else "r_knee")
    model = robot.servo(joint).name
    case = robot.case_of(joint)
    with Emulator.factory_new(v.protocol, 1, model=model) as emu:
        assert emu.ids == tuple(range(1, len(case) + 1))      # a dual case ships at 1 and 2
        emu.plug(0)
        assert {emu.registers_of(i)["id"] for i in range(len(case))} == set(emu.ids)
        assert main(["setup-motors", *_bus(emu, toml), "--joint", joint.name, "--yes"]) == 0
        out = capsys.readouterr().out
        assert f"at id 1{', id 2' if v.dual else ''}, {FACTORY_BAUD[model]} baud" in out
        emu.plug(None)          # power-cycle: what setup wrote was saved (EEPROM)
        emu.plug(0)
        for i, j in enumerate(case):
            regs = emu.registers_of(i)
            assert (regs["id"], regs["return_delay_time"]) == (j.servo_id, 0), j.name
            if "lock" in regs and v.protocol == "feetech":
                assert regs["lock"] == 1           # Feetech EEPROM locked again


@pytest.mark.parametrize("protocol", sorted(PROTOCOL_FAMILIES))
def test_scan_names_every_model(protocol: str, capsys: pytest.CaptureFixture[str]) -> None:
    """One chain a protocol holding every model it speaks (an XL-320 among X servos, an
    SCS among STS ones): the scan names each by what it answers."""
    names = sorted(n for n, m in MODELS.items() if m.family in PROTOCOL_FAMILIES[protocol])
    baud = 115_200 if protocol == "lx" else 1_000_000
    ids = list(range(1, len(names) + 1))
    emu = Emulator(protocol, ids=ids, baud=baud)
    emu.spec = replace(emu.spec, servos=tuple(
        ServoSpec(sid, name, MODELS[name].resolution // 2, 0, MODELS[name].resolution - 1,
                  baud) for sid, name in zip(ids, names, strict=True)))
    with emu:
        main(["scan", "--bus", protocol, "--port", emu.port, "--ids", f"1-{len(ids)}",
              "--json"])
    rows = json.loads(capsys.readouterr().out)
    if protocol == "lx":       # no model number on the wire: the robot file's model
        assert len(rows) == len(ids)
        return
    got = {r["id"]: r["model_name"] for r in rows}
    expected = dict(zip(ids, names, strict=True))
    # Two models answering one number are told apart by the robot file only: the 12 V
    # STS3215 reads as the STS3215 (both report 777).
    expected = {sid: "STS3215" if n == "STS3215-12V" else n for sid, n in expected.items()}
    assert got == expected
