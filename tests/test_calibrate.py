"""`biped calibrate`: the arithmetic, the TOML edit, and the command end to end on the
emulated chain (both protocols): right zero_ticks/sign/limits, comments kept, no goal
written, torque off throughout."""

from __future__ import annotations

import io
import math
from pathlib import Path

import pytest

import robot.cli as cli
from robot.commands import calibrate
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.config.toml_edit import edit_joints
from robot.errors import ConfigError
from robot.setup.calibration import (
    detect_sign,
    direction_words,
    hardware_range,
    limits_from_ends,
    probe_direction,
    wrapped_delta,
    zero_ticks,
)
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

RES = 4096
PER_RAD = RES / (2 * math.pi)
GOAL_ADDRESS = {"dynamixel": 116, "feetech": 42}     # X Goal Position, STS Goal Position
TORQUE_ADDRESS = {"dynamixel": 64, "feetech": 40}


@pytest.fixture(autouse=True)
def only_this_command(monkeypatch: pytest.MonkeyPatch) -> None:
    """Build the CLI from the command under test only (others may be unfinished)."""
    monkeypatch.setattr(cli, "COMMANDS", ("calibrate",))


# ------------------------------------------------------------------ pure arithmetic

def test_wrapped_delta_takes_the_short_way_round() -> None:
    assert wrapped_delta(100, 300, RES) == 200
    assert wrapped_delta(4000, 50, RES) == 146
    assert wrapped_delta(50, 4000, RES) == -146


def test_detect_sign_from_the_tick_change() -> None:
    assert detect_sign(2048, 2248, direction=1, resolution=RES).sign == 1
    assert detect_sign(2048, 1848, direction=1, resolution=RES).sign == -1
    assert detect_sign(2048, 1848, direction=-1, resolution=RES).sign == 1
    small = detect_sign(2048, 2090, direction=1, resolution=RES)   # 42 ticks < 0.1 rad
    assert small.sign is None and small.delta == 42


def test_zero_ticks_from_positions(robot: RobotConfig) -> None:
    positions = {j.servo_id: 2000 + j.servo_id for j in robot.joints}
    positions[robot.joint("r_knee").servo_id] = RES + 7        # multi-turn read-back wraps
    zeros = zero_ticks(positions, robot)
    assert zeros["l_elbow"] == 2000 + robot.joint("l_elbow").servo_id
    assert zeros["r_knee"] == 7


def test_limits_are_pulled_in_and_kept_inside_the_servo() -> None:
    # sign -1: 600 ticks below zero is +0.9204 rad, 300 above -0.4602; 0.02 rad margin
    lo, hi = limits_from_ends(2348 - 600, 2348 + 300, zero=2348, sign=-1, resolution=RES)
    assert (lo, hi) == (-0.440, 0.900)
    # the servo's own limit register stops it at 2348 + 200 ticks (0.3068 rad)
    lo, hi = limits_from_ends(2048, 2648, zero=2348, sign=1, resolution=RES,
                              servo_limits=(0, 2548))
    assert (lo, hi) == (-0.440, 0.306)
    assert hardware_range(4000, 1, RES) == pytest.approx((-math.pi, 95 / PER_RAD))


def test_probe_direction_and_words(robot: RobotConfig) -> None:
    assert probe_direction(robot, "r_knee") == 1
    assert probe_direction(robot, "l_elbow") == -1           # 0.1 rad of room past straight
    assert direction_words("l_hip_roll", 1) == "the foot swings toward the robot's left (outward)"
    assert direction_words("r_hip_roll", 1).endswith("(inward)")
    assert direction_words("r_knee", 1).startswith("the knee bends")


def test_edit_keeps_comments_and_changes_only_the_values() -> None:
    text = ("# my robot\n[joints.r_knee]  # right knee\nservo_id = 4\nsign = 1   # checked\n"
            "zero_ticks = 2048\n\n[rest]\nr_knee = 1.1\n")
    out = edit_joints(text, {"r_knee": {"sign": -1, "zero_ticks": 2100}})
    assert out == text.replace("sign = 1", "sign = -1").replace("2048", "2100")
    with pytest.raises(ConfigError, match="joints.tail: missing"):
        edit_joints(text, {"tail": {"sign": 1}})


# ------------------------------------------------------------------ end to end

def calib_args(emu: Emulator, robot_toml: Path, out: Path, *extra: str) -> list[str]:
    return ["calibrate", "--robot", str(robot_toml), "--bus", emu.protocol, "--port", emu.port,
            "--out", str(out), *extra]


def hold(emu: Emulator, sid: int, ticks: int) -> None:
    """The user holds servo ``sid`` at ``ticks`` (torque off: goal follows, nothing moves)."""
    emu.set_register(sid, "goal_position", ticks)
    emu.set_register(sid, "present_position", ticks)


def assert_no_goal_and_torque_off(emu: Emulator, robot: RobotConfig) -> None:
    packets = emu.log()
    assert not [p for p in packets if p.address == GOAL_ADDRESS[emu.protocol]]
    torque = [p for p in packets if p.address == TORQUE_ADDRESS[emu.protocol]
              and p.instruction in ("write", "sync_write")]
    assert torque and all(set(p.values.values()) == {0} for p in torque)
    assert {emu.registers(sid)["torque_enable"] for sid in robot.ids} == {0}


def test_zero_yes_writes_zero_ticks_keeping_comments(emu: Emulator, robot: RobotConfig,
                                                     robot_toml: Path, tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    for j in robot.joints:
        hold(emu, j.servo_id, 2000 + 5 * j.servo_id)         # r_hip_yaw 2005 ... l_elbow 2090
    emu.log(clear=True)
    out = tmp_path / "calibrated.toml"
    assert cli.main(calib_args(emu, robot_toml, out, "--zero", "--yes")) == 0
    assert f"wrote {out}" in capsys.readouterr().out
    new = load_robot(out)
    assert new.joint("r_hip_yaw").zero_ticks == 2005
    assert new.joint("r_knee").zero_ticks == 2020                 # id 4
    assert new.joint("l_elbow").zero_ticks == 2090                # id 18
    assert [j.sign for j in new.joints] == [j.sign for j in robot.joints]
    old_lines, new_lines = robot_toml.read_text().splitlines(), out.read_text().splitlines()
    assert len(old_lines) == len(new_lines)
    changed = [(a, b) for a, b in zip(old_lines, new_lines, strict=True) if a != b]
    assert all(a.startswith("zero_ticks = ") and b.startswith("zero_ticks = ")
               for a, b in changed)
    assert [ln for ln in new_lines if "#" in ln] == [ln for ln in old_lines if "#" in ln]
    assert_no_goal_and_torque_off(emu, robot)


def test_out_equal_to_robot_needs_overwrite(emu: Emulator, robot_toml: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    before = robot_toml.read_text()
    emu.log(clear=True)
    assert cli.main(calib_args(emu, robot_toml, robot_toml, "--zero", "--yes")) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--overwrite" in err
    assert robot_toml.read_text() == before and emu.log() == []
    assert cli.main(calib_args(emu, robot_toml, robot_toml, "--zero", "--yes",
                               "--overwrite")) == 0


def test_yes_needs_zero(emu: Emulator, robot_toml: Path, tmp_path: Path,
                        capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(calib_args(emu, robot_toml, tmp_path / "x.toml", "--yes")) == 2
    assert "--yes needs --zero" in capsys.readouterr().err


class Hands:
    """Scripted answers to the prompts: moves joints on the emulator like a user would.

    truth: the real sign of each joint (ticks per positive radian); ends: where each joint
    stops in step 3 [rad]; still: joints the user forgets to move.
    """

    def __init__(self, emu: Emulator, robot: RobotConfig, truth: dict[str, int], *,
                 ends: dict[str, tuple[float, float]] | None = None,
                 still: tuple[str, ...] = ()) -> None:
        self.emu, self.robot, self.truth = emu, robot, truth
        self.ends, self.still = ends or {}, still
        self.prompts: list[str] = []
        self.zero = {j.name: 2048 + 3 * j.servo_id for j in robot.joints}
        for j in robot.joints:
            hold(emu, j.servo_id, self.zero[j.name])

    def at(self, name: str, q: float) -> None:
        ticks = round(self.zero[name] + self.truth[name] * q * PER_RAD)
        hold(self.emu, self.robot.joint(name).servo_id, ticks)

    def __call__(self, prompt: str) -> str:
        self.prompts.append(prompt)
        name = prompt.split(" ", 1)[0]
        if name not in self.truth:
            name = prompt.split(" ")[1] if prompt.startswith("put ") else ""
        if prompt.startswith("put "):
            self.at(name, 0.0)
        elif "direction)" in prompt and name not in self.still:
            self.at(name, 0.4 if "(+ direction)" in prompt else -0.4)
        elif "one end" in prompt:
            self.at(name, self.ends[name][0])
        elif "the other end" in prompt:
            self.at(name, self.ends[name][1])
        return ""


def test_signs_are_confirmed_or_flipped_by_hand_moves(emu: Emulator, robot: RobotConfig,
                                                      robot_toml: Path, tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    truth = {j.name: j.sign for j in robot.joints}
    truth["r_knee"] = -truth["r_knee"]
    truth["l_elbow"] = -truth["l_elbow"]                      # probed in the - direction
    hands = Hands(emu, robot, truth, still=("r_ankle_roll",))
    emu.log(clear=True)
    out = tmp_path / "signed.toml"
    args = cli.build_parser().parse_args(calib_args(emu, robot_toml, out))
    assert calibrate.run(args, ask=hands) == 0
    new = load_robot(out)
    assert {j.name: j.sign for j in new.joints} == truth | {"r_ankle_roll": robot.joint(
        "r_ankle_roll").sign}
    assert {j.name: j.zero_ticks for j in new.joints} == hands.zero
    text = capsys.readouterr().out
    assert "r_knee: -" in text and "(flipped)" in text
    assert "r_ankle_roll: no move seen; sign kept" in text
    assert hands.prompts[0].startswith("step 1: hold the robot in its zero pose")
    assert any(p.startswith("l_elbow (id 18): move it so that the elbow bends")
               for p in hands.prompts)
    assert_no_goal_and_torque_off(emu, robot)


def test_limits_record_both_ends(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                                 tmp_path: Path) -> None:
    truth = {j.name: j.sign for j in robot.joints}
    ends = {j.name: (j.max_rad - 0.1, j.min_rad + 0.1) for j in robot.joints}   # any order
    hands = Hands(emu, robot, truth, ends=ends)
    out = tmp_path / "limits.toml"
    args = cli.build_parser().parse_args(calib_args(emu, robot_toml, out, "--limits"))
    assert calibrate.run(args, ask=hands) == 0
    new = load_robot(out)
    tick = 1 / PER_RAD
    for j, old in zip(new.joints, robot.joints, strict=True):
        # 0.1 rad inside the old limits, plus the 0.02 rad margin; a tick and 1e-3 rounding
        assert j.min_rad == pytest.approx(old.min_rad + 0.12, abs=tick + 1e-3), j.name
        assert j.max_rad == pytest.approx(old.max_rad - 0.12, abs=tick + 1e-3), j.name
        assert j.min_rad >= old.min_rad + 0.12 - tick and j.max_rad <= old.max_rad - 0.12 + tick
    assert_no_goal_and_torque_off(emu, robot)


def test_input_ending_early_writes_nothing(emu: Emulator, robot_toml: Path, tmp_path: Path,
                                           monkeypatch: pytest.MonkeyPatch,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr("sys.stdin", io.StringIO("\n"))     # Enter for step 1, then EOF
    out = tmp_path / "never.toml"
    assert cli.main(calib_args(emu, robot_toml, out)) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "input ended" in err and "nothing was written" in err
    assert not out.exists()
