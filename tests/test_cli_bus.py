"""`biped scan | torque | pose` end to end on the emulated chain."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from waiting import sleep_until, wait_for

import robot.cli as cli
from robot.bus.servo_map import ServoMap
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

REPO = Path(__file__).resolve().parent.parent


@pytest.fixture(autouse=True)
def only_bus_commands(monkeypatch: pytest.MonkeyPatch) -> None:
    """Build the CLI from the commands under test only (others may be unfinished)."""
    monkeypatch.setattr(cli, "COMMANDS", ("scan", "torque", "pose"))


#: Goal Position address, from the manuals (XL430-W250 116; STS3215 42).
GOAL_ADDRESS = {"dynamixel": 116, "feetech": 42}


def goal_writes(emu: Emulator) -> list:
    return [p for p in emu.log() if p.instruction == "sync_write"
            and p.address == GOAL_ADDRESS[emu.protocol]]


def bus_args(emu: Emulator, robot_toml: Path) -> list[str]:
    return ["--bus", emu.protocol, "--port", emu.port, "--robot", str(robot_toml)]


def test_scan_json_is_a_clean_list(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                                   capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["scan", *bus_args(emu, robot_toml), "--ids", "1-20", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["id"] for r in rows] == sorted(robot.ids)
    assert {r["model"] for r in rows} == {robot.bus.servo.number}
    assert rows[6]["joint"] == "l_hip_yaw"


def test_scan_table_names_missing_joints(emu: Emulator, robot_toml: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    emu.set_faults(missing_ids=[7, 12])
    assert cli.main(["scan", *bus_args(emu, robot_toml)]) == 1    # incomplete: exit 1
    out = capsys.readouterr().out
    assert "16 servo(s)" in out
    assert "missing joints (2 of 18; exit status 1): l_hip_yaw (id 7), l_ankle_roll (id 12)" \
        in out


def test_scan_at_wrong_baud_names_the_rate(emu: Emulator, robot_toml: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    other = 57600 if emu.protocol == "dynamixel" else 500000
    emu.set_baud(other)
    # The hardware does not answer as configured: a bus error (1), not bad input (2).
    assert cli.main(["scan", *bus_args(emu, robot_toml), "--ids", "1-4", "--json"]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert f"--baud {other}" in captured.err


def test_torque_on_holds_present_position_then_off(emu: Emulator, robot: RobotConfig,
                                                   robot_toml: Path) -> None:
    assert cli.main(["torque", "on", *bus_args(emu, robot_toml)]) == 0
    regs = [emu.registers(i) for i in robot.ids]
    assert all(r["torque_enable"] == 1 for r in regs)
    assert all(r["goal_position"] == r["present_position"] for r in regs)
    assert cli.main(["torque", "off", *bus_args(emu, robot_toml)]) == 0
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}


def test_pose_rest_ramps_within_slew_and_ends_at_rest(
        emu: Emulator, robot: RobotConfig, robot_toml: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    sm = ServoMap(robot)
    speed, rate = 3.0, 50.0
    emu.log(clear=True)
    assert cli.main(["pose", "rest", *bus_args(emu, robot_toml), "--speed", str(speed),
                     "--rate", str(rate)]) == 0
    assert "torque left ON" in capsys.readouterr().out
    writes = goal_writes(emu)      # (torque on also sync-writes the gains first)
    assert len(writes) > 20
    ticks = np.array([[p.values[i] for i in robot.ids] for p in writes])
    assert np.array_equal(ticks[0], [2048] * len(robot.ids))  # starts where it stood
    max_step = np.minimum(sm.max_speed, speed) / rate * sm.ticks_per_rad
    assert np.all(np.abs(np.diff(ticks, axis=0)) <= np.ceil(max_step) + 1)
    rest = sm.goals(sm.vector(robot.rest).tolist())
    assert dict(zip(robot.ids, ticks[-1].tolist(), strict=True)) == rest
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {1}


def test_pose_ctrl_c_stops_and_holds(emu: Emulator, robot: RobotConfig,
                                     robot_toml: Path) -> None:
    code = ("import sys, robot.cli as c; c.COMMANDS = ('pose',); "
            "sys.exit(c.main(sys.argv[1:]))")
    cmd = [sys.executable, "-c", code, "pose", "rest", *bus_args(emu, robot_toml),
           "--speed", "1.0", "--rate", "50"]
    proc = subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env={**os.environ, "MUJOCO_GL": "egl"})
    def knee_goal() -> int:
        writes = goal_writes(emu)
        return writes[-1].values[4] if writes else 2048

    rest_knee = ServoMap(robot).goals(ServoMap(robot).vector(robot.rest).tolist())[4]
    # Well into the 2 s ramp: the knee's goal a tenth of the way to rest.
    try:
        assert wait_for(lambda: knee_goal() > 2048 + (rest_knee - 2048) / 10, timeout_s=60,
                        stop=lambda: proc.poll() is not None), "the ramp never started"
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert "holding" in out
    n = len([p for p in emu.log() if p.instruction == "sync_write"])
    sleep_until(time.monotonic() + 0.1)     # 0.1 s later: five ticks at 50 Hz, no write
    assert len([p for p in emu.log() if p.instruction == "sync_write"]) == n  # stopped
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {1}
    knee = emu.registers(4)["goal_position"]
    assert 2048 < knee < ServoMap(load_robot(robot_toml)).goals(
        ServoMap(robot).vector(robot.rest).tolist())[4]  # mid-ramp, not snapped
