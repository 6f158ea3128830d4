"""The `biped` commands on an LX chain (the emulator's, on a pty): scan, setup-motors,
calibrate, monitor, torque, pose and walk, judged at the wire (what each servo was told,
and its load state at every end)."""

from __future__ import annotations

import io
import json
import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from contextlib import redirect_stdout
from pathlib import Path

import pytest
from waiting import wait_for

import robot.cli as cli
from robot.bus.servo_map import ServoMap
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

REPO = Path(__file__).resolve().parent.parent
MOVES = "move_time_write"


@pytest.fixture
def protocol() -> str:
    return "lx"


def bus_args(emu: Emulator, robot_toml: Path) -> list[str]:
    return ["--bus", "lx", "--port", emu.port, "--robot", str(robot_toml)]


def loads(emu: Emulator, robot: RobotConfig) -> set[int]:
    return {emu.registers(i)["torque_enable"] for i in robot.ids}


def inside_limits(emu: Emulator, robot: RobotConfig) -> bool:
    """Every goal the servos were sent lies inside its joint's tick range."""
    sm = ServoMap(robot)
    window = {i: (int(lo), int(hi)) for i, lo, hi in zip(sm.ids, sm.tick_min, sm.tick_max,
                                                          strict=True)}
    return all(window[i][0] <= v <= window[i][1] for p in emu.log()
               if p.instruction == MOVES for i, v in p.values.items())


def test_scan_names_every_joint_and_its_model(emu: Emulator, robot: RobotConfig,
                                              robot_toml: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    emu.set_faults(missing_ids=[12])
    # A joint that does not answer makes the scan incomplete: exit 1 (README's exit codes).
    assert cli.main(["scan", *bus_args(emu, robot_toml), "--json"]) == 1
    rows = json.loads(capsys.readouterr().out)
    assert [r["id"] for r in rows] == [i for i in robot.ids if i != 12]
    assert {r["model_name"] for r in rows} == {"LX-16A (config)"}
    assert rows[0]["joint"] == "r_hip_yaw"
    assert cli.main(["scan", *bus_args(emu, robot_toml)]) == 1
    assert "l_ankle_roll (id 12)" in capsys.readouterr().out.split("missing joints")[1]


def test_setup_motors_gives_a_new_servo_its_id_and_refuses_two(
        robot_toml: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with Emulator.factory_new("lx", 2) as fresh:
        args = ["setup-motors", "--robot", str(robot_toml), "--bus", "lx", "--port",
                fresh.port, "--joint", "r_knee", "--yes"]
        fresh.plug(0)
        assert cli.main(args) == 0
        assert fresh.registers_of(0)["id"] == 4 and fresh.registers_of(0)["torque_enable"] == 0
        assert "r_knee: id 4 at 115200 baud, checked (id 1 -> 4)" in capsys.readouterr().out
        fresh.plug_all()                      # a set-up servo and a new one: refused
        fresh.log(clear=True)
        assert cli.main(args) == 2
        assert "nothing was written" in capsys.readouterr().err
        assert not [p for p in fresh.log() if p.instruction == "id_write"]


def test_calibrate_zero_reads_where_the_horns_are(emu: Emulator, robot: RobotConfig,
                                                  robot_toml: Path, tmp_path: Path) -> None:
    emu.set_register(4, "present_position", 517)        # a horn a few steps off centre
    out = tmp_path / "calibrated.toml"
    assert cli.main(["calibrate", *bus_args(emu, robot_toml), "--out", str(out), "--zero",
                     "--yes"]) == 0
    assert load_robot(out).joint("r_knee").zero_ticks == 517
    assert loads(emu, robot) == {0}
    assert not [p for p in emu.log() if p.instruction == MOVES]


def test_monitor_once_reads_every_joint_torque_off(emu: Emulator, robot: RobotConfig,
                                                   robot_toml: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["monitor", *bus_args(emu, robot_toml), "--once", "--json"]) == 0
    text = capsys.readouterr().out
    assert "r_knee" in text and "l_elbow" in text
    assert loads(emu, robot) == {0}


def test_torque_on_holds_then_off(emu: Emulator, robot: RobotConfig, robot_toml: Path) -> None:
    assert cli.main(["torque", "on", *bus_args(emu, robot_toml)]) == 0
    regs = [emu.registers(i) for i in robot.ids]
    assert {r["torque_enable"] for r in regs} == {1}
    assert all(r["goal_position"] == r["present_position"] for r in regs)
    assert cli.main(["torque", "off", *bus_args(emu, robot_toml)]) == 0
    assert loads(emu, robot) == {0}


def test_pose_moves_in_steps_and_holds(emu: Emulator, robot: RobotConfig,
                                       robot_toml: Path) -> None:
    assert cli.main(["pose", "rest", *bus_args(emu, robot_toml), "--rate", "40"]) == 0
    moves = [p for p in emu.log() if p.instruction == MOVES and p.ids == (4,)]
    assert len(moves) > 5 and inside_limits(emu, robot)
    assert loads(emu, robot) == {1}                     # pose holds at the end
    knee = [p.values[4] for p in moves]
    assert max(abs(b - a) for a, b in zip(knee, knee[1:], strict=False)) < 25   # no snap


def walk(emu: Emulator, robot_toml: Path, *extra: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), pytest.MonkeyPatch.context() as mp:
        mp.setattr(sys, "stderr", err)
        code = cli.main(["walk", *bus_args(emu, robot_toml), "--json", *extra])
    return code, out.getvalue(), err.getvalue()


def test_walk_streams_one_move_per_servo_and_ends_unloaded(
        emu: Emulator, robot: RobotConfig, robot_toml: Path) -> None:
    code, out, err = walk(emu, robot_toml, "--rate", "50", "--seconds", "2")
    assert code == 0, err
    assert json.loads(out)["stop_reason"] == "completed"
    counts = emu.counters()
    assert counts[MOVES] >= 18 * 90 and counts[MOVES] % 18 == 0
    assert inside_limits(emu, robot)
    assert loads(emu, robot) == {0}


def test_walk_at_a_rate_the_wire_cannot_carry_is_one_line_and_nothing_moves(
        emu: Emulator, robot: RobotConfig, robot_toml: Path) -> None:
    code, out, err = walk(emu, robot_toml, "--rate", "200", "--seconds", "2")
    assert code == 2 and out == ""
    assert "--rate 200: 18 LX servos" in err and len(err.strip().splitlines()) == 1
    assert not [p for p in emu.log() if p.instruction.endswith("_write")]


@pytest.fixture
def walking(emu: Emulator, robot_toml: Path) -> Iterator[subprocess.Popen[str]]:
    cmd = [sys.executable, "-m", "robot.cli", "walk", *bus_args(emu, robot_toml), "--rate",
           "50", "--seconds", "60", "--json"]
    proc = subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env={**os.environ, "MUJOCO_GL": "egl"})
    yield proc
    if proc.poll() is None:
        proc.kill()
    proc.communicate()


@pytest.mark.parametrize(("sig", "code"), [(signal.SIGTERM, 143), (signal.SIGKILL, -9)])
def test_a_stopped_walk_leaves_the_servos_safe(emu: Emulator, robot: RobotConfig,
                                               walking: subprocess.Popen[str],
                                               sig: signal.Signals, code: int) -> None:
    assert wait_for(lambda: emu.counters().get(MOVES, 0) >= 18 * 50, timeout_s=60,
                    stop=lambda: walking.poll() is not None), walking.stderr
    walking.send_signal(sig)
    assert walking.wait(timeout=30) == code
    if sig == signal.SIGTERM:
        assert loads(emu, robot) == {0}
    else:
        # killed outright nothing can unload: no watchdog in the servo, so each holds its
        # last goal with torque on (docs/hardware.md, "LX servos": cut the servo power)
        assert loads(emu, robot) == {1}
    assert inside_limits(emu, robot)
