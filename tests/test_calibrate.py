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
    fit_limits,
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


def test_fit_limits_cuts_to_the_ticks_the_servo_has() -> None:
    # zero 1786, sign +1: tick 0 lies 1786 x 2 pi / 4096 = 2.73969 rad below zero
    assert fit_limits(-3.0, 1.5, zero=1786, sign=1, resolution=RES) == (-2.739, 1.5)
    # sign -1: tick 0 is +2.73969 rad; tick 4095 is -2309 x 2 pi / 4096 = -3.542 (< -pi)
    assert fit_limits(-3.0, 3.0, zero=1786, sign=-1, resolution=RES) == (-3.0, 2.739)
    assert fit_limits(-0.5, 0.5, zero=2048, sign=1, resolution=RES) == (-0.5, 0.5)
    assert fit_limits(0.0, 2.3, zero=4095, sign=1, resolution=RES) is None   # nothing reached
    # AX-12A, 1024 ticks over 300 deg (195.57 ticks/rad): zero 40 leaves 40 / 195.57 =
    # 0.20453 rad below it
    per_rad = 1024 / math.radians(300)
    assert fit_limits(-2.5, 1.5, zero=40, sign=1, resolution=1024,
                      ticks_per_rad=per_rad) == (-0.204, 1.5)


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
    # the bundled robot's name becomes the file's: the user's robot is not biped18-*
    assert (f'name = "{robot.name}"', 'name = "calibrated"') in changed
    assert new.name == "calibrated"
    assert all(a.startswith("zero_ticks = ") and b.startswith("zero_ticks = ")
               for a, b in changed if not a.startswith("name = "))
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
    stops in step 3 [rad]; still: joints the user forgets to move in step 2; stuck: how
    many times each joint is left at zero when asked for its ends in step 3.
    """

    def __init__(self, emu: Emulator, robot: RobotConfig, truth: dict[str, int], *,
                 ends: dict[str, tuple[float, float]] | None = None,
                 still: tuple[str, ...] = (), stuck: dict[str, int] | None = None) -> None:
        self.emu, self.robot, self.truth = emu, robot, truth
        self.ends, self.still, self.stuck = ends or {}, still, dict(stuck or {})
        self.prompts: list[str] = []
        self.moving = True
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
        elif "one end" in prompt or "the other end" in prompt:
            first = "one end" in prompt
            if first:
                self.moving = self.stuck.get(name, 0) <= 0
                self.stuck[name] = self.stuck.get(name, 0) - 1
            # a stuck joint reads zero at both ends (a dead servo, or the user skipped it)
            self.at(name, self.ends[name][0 if first else 1] if self.moving else 0.0)
        return ""


def test_signs_are_confirmed_or_flipped_by_hand_moves(emu: Emulator, robot: RobotConfig,
                                                      robot_toml: Path, tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    truth = {j.name: j.sign for j in robot.joints}
    truth["r_knee"] = -truth["r_knee"]
    truth["l_elbow"] = -truth["l_elbow"]                      # probed in the - direction
    hands = Hands(emu, robot, truth)
    emu.log(clear=True)
    out = tmp_path / "signed.toml"
    args = cli.build_parser().parse_args(calib_args(emu, robot_toml, out))
    assert calibrate.run(args, ask=hands) == 0
    new = load_robot(out)
    assert {j.name: j.sign for j in new.joints} == truth
    assert {j.name: j.zero_ticks for j in new.joints} == hands.zero
    text = capsys.readouterr().out
    assert "r_knee: -" in text and "(flipped)" in text and "NOT measured" not in text
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


def test_a_joint_that_never_moved_is_flagged_and_the_exit_says_incomplete(
        emu: Emulator, robot: RobotConfig, robot_toml: Path, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    """A dead servo or a skipped joint: its sign is not measured. The file still gets every
    measured value (the flipped r_knee, every zero), the summary flags the two joints, and
    the exit code is 1 (incomplete)."""
    truth = {j.name: j.sign for j in robot.joints}
    truth["r_knee"] = -truth["r_knee"]
    hands = Hands(emu, robot, truth, still=("r_ankle_roll", "l_elbow"))
    out = tmp_path / "signed.toml"
    args = cli.build_parser().parse_args(calib_args(emu, robot_toml, out))
    assert calibrate.run(args, ask=hands) == 1
    new = load_robot(out)
    assert {j.name: j.sign for j in new.joints} == truth           # the still ones: as before
    assert {j.name: j.zero_ticks for j in new.joints} == hands.zero
    captured = capsys.readouterr()
    rows = {line.split()[0]: line for line in captured.out.splitlines() if line.startswith(
        tuple(truth))}
    flagged = {name for name, line in rows.items() if "NOT measured" in line}
    assert flagged == {"r_ankle_roll", "l_elbow"}
    assert "r_ankle_roll: no move seen in 3 tries; sign NOT measured" in captured.out
    err = captured.err.strip()
    assert len(err.splitlines()) == 1 and "incomplete" in err, err
    assert "r_ankle_roll (sign)" in err and "l_elbow (sign)" in err
    assert sum(p.startswith("r_ankle_roll (id 6): move it") for p in hands.prompts) == 3


def test_limits_ask_again_at_once_and_keep_every_measured_joint(
        emu: Emulator, robot: RobotConfig, robot_toml: Path, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    """In step 3 r_knee stays put once (asked again at once, then measured); l_knee never
    moves: its limits stay as they were, flagged, exit 1, and the zeros, signs and the other
    joints' limits are written (the file was refused whole before, after all 54 prompts)."""
    truth = {j.name: j.sign for j in robot.joints}
    ends = {j.name: (j.max_rad - 0.1, j.min_rad + 0.1) for j in robot.joints}
    hands = Hands(emu, robot, truth, ends=ends, stuck={"r_knee": 1, "l_knee": 3})
    out = tmp_path / "limits.toml"
    args = cli.build_parser().parse_args(calib_args(emu, robot_toml, out, "--limits"))
    assert calibrate.run(args, ask=hands) == 1
    step3 = [p for p in hands.prompts if "free range" in p or p.startswith("put ")][
        len(robot.joints):]                                      # after step 2's put-backs
    knee = [p.split(":")[1].strip()[:24] for p in step3 if p.startswith("r_knee")]
    assert knee == ["hold it at one end of it", "hold it at the other end",
                    "hold it at one end of it", "hold it at the other end"]
    assert sum(p.startswith("l_knee (id 10): hold it at one end") for p in step3) == 3
    new = load_robot(out)
    assert {j.name: j.zero_ticks for j in new.joints} == hands.zero
    tick = 1 / PER_RAD
    old_knee = robot.joint("r_knee")
    assert new.joint("r_knee").min_rad == pytest.approx(old_knee.min_rad + 0.12,
                                                        abs=tick + 1e-3)
    l_knee = new.joint("l_knee")
    assert (l_knee.min_rad, l_knee.max_rad) == (robot.joint("l_knee").min_rad,
                                                robot.joint("l_knee").max_rad)
    captured = capsys.readouterr()
    assert "r_knee: the two ends are only 0.00 rad apart" in captured.out
    assert "l_knee: limits NOT measured in 3 tries" in captured.out
    assert "l_knee (limits)" in captured.err and "r_knee" not in captured.err
    assert_no_goal_and_torque_off(emu, robot)


def test_zero_with_a_horn_off_centre_narrows_the_limits_and_writes(
        emu: Emulator, robot: RobotConfig, robot_toml: Path, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    """The issue's shoulder: zero_ticks 1786 puts the bundled -3.0 rad below tick 0
    (1786 - 3.0 x 4096 / 2 pi = -170). Tick 0 is 1786 ticks below zero: 1786 x 2 pi / 4096
    = 2.73969 rad, so min_rad -2.739 (rounded inward); max_rad +1.5 fits and stays. l_knee
    at 3400: tick 4095 is 695 ticks = 1.06612 rad above zero, so its limits become
    [0, 1.066] and its rest angle 1.1 moves to 1.066. r_knee at 4095: the servo reaches
    nothing of [0, 2.3] (sign +1), so that joint keeps its old values and the exit is 1."""
    for j in robot.joints:
        hold(emu, j.servo_id, 2048)
    hold(emu, robot.joint("r_shoulder_pitch").servo_id, 1786)
    hold(emu, robot.joint("l_knee").servo_id, 3400)
    out = tmp_path / "calibrated.toml"
    assert cli.main(calib_args(emu, robot_toml, out, "--zero", "--yes")) == 0
    new = load_robot(out)
    shoulder = new.joint("r_shoulder_pitch")
    assert (shoulder.zero_ticks, shoulder.min_rad, shoulder.max_rad) == (1786, -2.739, 1.5)
    knee = new.joint("l_knee")
    assert (knee.zero_ticks, knee.min_rad, knee.max_rad) == (3400, 0.0, 1.066)
    assert new.rest["l_knee"] == 1.066
    unchanged = [j for j in new.joints if j.name not in ("r_shoulder_pitch", "l_knee")]
    assert all((j.min_rad, j.max_rad) == (robot.joint(j.name).min_rad,
                                          robot.joint(j.name).max_rad) for j in unchanged)
    text = capsys.readouterr().out
    assert ("r_shoulder_pitch: limits [-3.000, +1.500] -> [-2.739, +1.500] rad: from "
            "zero_ticks 1786") in text
    assert "rest.l_knee: +1.100 -> +1.066 rad" in text

    hold(emu, robot.joint("r_knee").servo_id, 4095)
    again = tmp_path / "again.toml"
    assert cli.main(calib_args(emu, robot_toml, again, "--zero", "--yes")) == 1
    captured = capsys.readouterr()
    kept = load_robot(again).joint("r_knee")
    assert kept.zero_ticks == robot.joint("r_knee").zero_ticks
    assert load_robot(again).joint("r_shoulder_pitch").min_rad == -2.739
    assert "r_knee: from zero_ticks 4095 its servo reaches" in captured.out
    assert "r_knee (zero, sign and limits" in captured.err
    assert_no_goal_and_torque_off(emu, robot)


def test_the_closing_hint_names_the_bus_and_port(emu: Emulator, robot_toml: Path,
                                                 tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "mine.toml"
    assert cli.main(calib_args(emu, robot_toml, out, "--zero", "--yes")) == 0
    hint = f"`biped monitor --robot {out} --bus {emu.protocol} --port {emu.port}`"
    assert hint in capsys.readouterr().out
    assert load_robot(out).name == "mine"
