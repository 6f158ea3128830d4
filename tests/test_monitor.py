"""`biped monitor` end to end on the emulated chain (both protocols): the angles it prints
against a hand computation from the robot file, torque off, never a goal on the wire."""

from __future__ import annotations

import json
import math
import os
import re
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path
from typing import Any

import pytest
from waiting import wait_for

import robot.cli as cli
from robot.commands.monitor import next_deadline
from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

REPO = Path(__file__).resolve().parent.parent
#: Goal Position per family, from the manuals (Dynamixel X e-Manual, Feetech STS3215 memory
#: table): written here by hand, not taken from robot/bus/tables.py.
GOAL_ADDRESS = {"dynamixel": 116, "feetech": 42}
WRITES = {"write", "sync_write", "reg_write", "bulk_write"}
#: Calibration offsets put into the test robot so that zero_ticks and sign both matter.
OFFSETS = {"r_knee": 2100, "l_hip_pitch": 1990, "r_elbow": 2500}


@pytest.fixture(autouse=True)
def only_monitor(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cli, "COMMANDS", ("monitor",))


@pytest.fixture
def calibrated_toml(robot_toml: Path) -> Path:
    """The test robot with some joints' zero_ticks moved off 2048."""
    text = robot_toml.read_text()
    for joint, zero in OFFSETS.items():
        text, n = re.subn(rf"(\[joints\.{joint}\][^\[]*?zero_ticks = )\d+",
                          rf"\g<1>{zero}", text)
        assert n == 1, joint
    robot_toml.write_text(text)
    return robot_toml


def by_hand(path: Path, joint: str, ticks: int) -> float:
    """q from ticks = zero_ticks + sign * q * 4096 / (2 pi), reading the robot file."""
    j = tomllib.loads(path.read_text())["joints"][joint]
    return float((ticks - j["zero_ticks"]) * j["sign"] * 2 * math.pi / 4096)


def args(emu: Emulator, path: Path, *more: str) -> list[str]:
    return ["monitor", "--bus", emu.protocol, "--port", emu.port, "--robot", str(path), *more]


def goal_writes(emu: Emulator) -> list[Any]:
    goal = GOAL_ADDRESS[emu.protocol]
    return [p for p in emu.log() if p.instruction in WRITES and p.address is not None
            and p.address <= goal < p.address + max(p.length or 1, 1)]


def assert_limp_and_no_goal(emu: Emulator, robot: RobotConfig) -> None:
    assert goal_writes(emu) == []
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}


def test_once_json_angles_match_the_robot_file(
        emu: Emulator, robot: RobotConfig, calibrated_toml: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    present = {3: 2300, 4: 2700, 9: 1800, 15: 2400, 8: 2048 + 512}
    for sid, ticks in present.items():  # held there with torque on until monitor starts
        emu.set_register(sid, "goal_position", ticks)
        emu.set_register(sid, "present_position", ticks)
        emu.set_register(sid, "torque_enable", 1)
    emu.log(clear=True)
    assert cli.main(args(emu, calibrated_toml, "--once", "--json")) == 0
    out = capsys.readouterr().out
    assert len(out.splitlines()) == 1
    table = {r["joint"]: r for r in json.loads(out)["joints"]}
    assert [r["id"] for r in table.values()] == list(robot.ids)
    for j in robot.joints:
        ticks = present.get(j.servo_id, 2048)
        row = table[j.name]
        assert row["ticks"] == ticks
        assert row["rad"] == pytest.approx(by_hand(calibrated_toml, j.name, ticks), abs=1e-12)
        assert row["deg"] == pytest.approx(math.degrees(row["rad"]), abs=1e-9)
    assert table["r_knee"]["rad"] == pytest.approx((2700 - 2100) * 2 * math.pi / 4096)
    assert table["l_hip_roll"]["rad"] == pytest.approx(-math.pi / 4)  # sign -1
    assert_limp_and_no_goal(emu, robot)


def test_once_table_marks_limits_and_hardware_errors(
        emu: Emulator, robot: RobotConfig, calibrated_toml: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    knee = robot.joint_by_id(4)
    assert knee is not None
    beyond = 2100 + round((knee.max_rad + 0.2) * 4096 / (2 * math.pi))  # sign +1
    emu.set_register(4, "present_position", beyond)
    emu.set_faults(hw_error={5: "overheating"})
    assert cli.main(args(emu, calibrated_toml, "--once")) == 0
    lines = capsys.readouterr().out.splitlines()
    knee_line = next(line for line in lines if line.startswith("r_knee "))
    deg = math.degrees(by_hand(calibrated_toml, "r_knee", beyond))
    assert f"{deg:+.1f}" in knee_line and ">MAX" in knee_line and str(beyond) in knee_line
    ankle = next(line for line in lines if line.startswith("r_ankle_pitch "))
    assert ankle.split()[-1] == "overheating"
    assert all(line.split()[-1] == "-" for line in lines
               if line.split()[0] in robot.joint_names and line.split()[0] not in
               ("r_ankle_pitch", "r_knee"))
    assert lines[-1] == "outside limits: r_knee >MAX; errors: r_ankle_pitch: overheating"
    assert_limp_and_no_goal(emu, robot)


def test_live_json_until_ctrl_c(emu: Emulator, robot: RobotConfig, robot_toml: Path) -> None:
    for sid in robot.ids:
        emu.set_register(sid, "torque_enable", 1)
    emu.log(clear=True)
    code = ("import sys, robot.cli as c; c.COMMANDS = ('monitor',); "
            "sys.exit(c.main(sys.argv[1:]))")
    proc = subprocess.Popen([sys.executable, "-c", code, *args(emu, robot_toml, "--json",
                                                                "--rate", "20")],
                            cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env={**os.environ, "MUJOCO_GL": "egl"})
    assert proc.stdout is not None
    first = json.loads(proc.stdout.readline())
    emu.set_register(6, "present_position", 2148)  # moved by hand while watching
    frames = [first]
    end = time.monotonic() + 10
    while time.monotonic() < end:
        frames.append(json.loads(proc.stdout.readline()))
        if frames[-1]["joints"][5]["ticks"] == 2148 and len(frames) >= 5:
            break
    proc.send_signal(signal.SIGINT)
    rest, err = proc.communicate(timeout=10)
    assert proc.returncode == 130, err
    frames += [json.loads(line) for line in rest.splitlines()]
    assert frames[-1]["joints"][5]["ticks"] == 2148
    ts = [f["t"] for f in frames]
    assert ts == sorted(ts) and ts[0] == 0.0
    assert all((t + 1e-6) / 0.05 % 1 < 0.8 for t in ts), ts  # on the 20 Hz grid
    assert_limp_and_no_goal(emu, robot)


def test_bad_rate_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["monitor", "--bus", "feetech", "--port", "/dev/null", "--rate",
                     "0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--rate" in err


def test_next_deadline_stays_on_the_grid() -> None:
    assert next_deadline(10.0, 0.5, 10.01) == 10.5
    assert next_deadline(10.0, 0.5, 10.5) == 11.0
    assert next_deadline(10.0, 0.5, 11.74) == 12.0  # a slow read skips missed deadlines
    assert next_deadline(10.0, 0.5, 9.0) == 10.5


def test_live_table_refreshes_in_place_on_a_terminal(emu: Emulator, robot: RobotConfig,
                                                     robot_toml: Path) -> None:
    """On a terminal each refresh moves the cursor up over the last table and redraws it."""
    import pty
    import threading

    master, slave = pty.openpty()
    chunks: list[bytes] = []

    def drain() -> None:  # a terminal that is read, as a real one is
        while True:
            try:
                data = os.read(master, 65536)
            except OSError:
                return
            if not data:
                return
            chunks.append(data)

    reader = threading.Thread(target=drain, daemon=True)
    reader.start()
    code = ("import sys, robot.cli as c; c.COMMANDS = ('monitor',); "
            "sys.exit(c.main(sys.argv[1:]))")
    proc = subprocess.Popen([sys.executable, "-c", code, *args(emu, robot_toml, "--rate",
                                                                "20")],
                            cwd=REPO, stdout=slave, stderr=subprocess.PIPE,
                            env={**os.environ, "MUJOCO_GL": "egl"})
    try:
        assert wait_for(lambda: b"".join(chunks).count(b"\x1b[J") >= 3, timeout_s=60,
                        stop=lambda: proc.poll() is not None), b"".join(chunks)
        proc.send_signal(signal.SIGINT)
        assert proc.wait(10) == 130
    finally:
        if proc.poll() is None:
            proc.kill()
        os.close(slave)
    reader.join(5)  # the rest of the output, up to the terminal's hang-up
    os.close(master)
    out = b"".join(chunks).decode()
    lines_per_table = 2 + len(robot.ids) + 2  # title, header, joints, gains, summary
    assert out.count(f"\x1b[{lines_per_table}F\x1b[J") >= 3
    assert out.count("r_knee ") == out.count("\x1b[J") + 1
    assert_limp_and_no_goal(emu, robot)
