"""Keyframes: interpolation by its defining properties, sequence files and their one-line
errors, layering on the walking gait in the simulation, and posing by hand on the pty
emulator (real vendor SDKs): the released limb's present positions, set in the emulator
as a hand would, are what gets captured."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from bus_harness import PATIENT_TIMEOUT_MS
from hypothesis import given, settings
from hypothesis import strategies as st

import robot.cli as cli
from robot.commands import capture as capture_cmd
from robot.config.bundled import DEFAULT_ROBOT
from robot.config.gait_file import load_gait
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.motion.interp import min_jerk, smooth
from robot.motion.keyframes import load_sequence
from robot.motion.takes import read_take
from robot.previs.plots import read_table
from robot.servo.models import MODELS
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

#: Reply timeout [ms] of this module's robot files (the harness reads it): no servo is made
#: silent here (the capture's hold missed 100 ms at load).
REPLY_TIMEOUT_MS = PATIENT_TIMEOUT_MS

WAVE = """name = "wave"
[[keyframe]]
t = 0.0
r_shoulder_pitch = 0.0
r_elbow = -0.2
[[keyframe]]
t = 1.5
r_shoulder_pitch = -1.0
r_elbow = -0.9
[[keyframe]]
t = 3.0
r_shoulder_pitch = -0.2
r_elbow = -0.3
"""


def default_robot() -> RobotConfig:
    return load_robot(DEFAULT_ROBOT)


# ------------------------------------------------------------------ interpolation


def test_min_jerk_is_the_quintic_with_rests_at_the_keys() -> None:
    times = np.array([0.0, 2.0, 3.0])
    values = np.array([[0.0], [1.0], [-0.5]])
    t = np.linspace(0, 3, 301)
    q = min_jerk(times, values, t)[:, 0]
    # Flash & Hogan: x(s) = x0 + (x1 - x0)(10 s^3 - 15 s^4 + 6 s^5), written out here.
    for ti, qi in zip(t, q, strict=True):
        k = 0 if ti < 2.0 else 1
        s = (ti - times[k]) / (times[k + 1] - times[k])
        want = values[k, 0] + (values[k + 1, 0] - values[k, 0]) * (
            10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5)
        assert qi == pytest.approx(want, abs=1e-12)
    # Mid-segment: halfway; peak speed 1.875 x the mean; zero speed at the keys.
    assert min_jerk(times, values, np.array([1.0]))[0, 0] == pytest.approx(0.5)
    v = np.gradient(q, t)
    assert np.max(v[:200]) == pytest.approx(1.875 * 0.5, rel=2e-3)
    assert abs(v[0]) < 1e-3 and abs(v[200]) < 0.05
    assert min_jerk(times, values, np.array([-1.0, 9.0]))[:, 0].tolist() == [0.0, -0.5]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-2, 2), min_size=3, max_size=8),
       st.lists(st.floats(0.1, 3.0), min_size=7, max_size=7))
def test_smooth_passes_the_keys_without_overshoot(vals: list[float], gaps: list[float]) -> None:
    times = np.concatenate([[0.0], np.cumsum(gaps[:len(vals) - 1])])
    values = np.array(vals)[:, None]
    q_keys = smooth(times, values, times)[:, 0]
    assert np.allclose(q_keys, vals, atol=1e-12)
    t = np.linspace(0, times[-1], 2000)
    q = smooth(times, values, t)[:, 0]
    seg = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    lo = np.minimum(values[seg, 0], values[seg + 1, 0])
    hi = np.maximum(values[seg, 0], values[seg + 1, 0])
    assert np.all(q >= lo - 1e-9) and np.all(q <= hi + 1e-9)  # monotone per segment
    # Continuous velocity across the keys (one-sided difference quotients agree).
    h = 1e-8  # the one-sided quotients differ by ~curvature x h
    for k in times[1:-1]:
        left = (smooth(times, values, np.array([k]))[0, 0]
                - smooth(times, values, np.array([k - h]))[0, 0]) / h
        right = (smooth(times, values, np.array([k + h]))[0, 0]
                 - smooth(times, values, np.array([k]))[0, 0]) / h
        assert left == pytest.approx(right, abs=1e-3 * (1 + abs(left)))


# ------------------------------------------------------------------ sequence files


def test_toml_and_json_read_the_same(tmp_path: Path) -> None:
    robot = default_robot()
    a = tmp_path / "wave.toml"
    a.write_text(WAVE)
    seq = load_sequence(a, robot)
    b = tmp_path / "wave.json"
    b.write_text(json.dumps(seq.as_json()))
    again = load_sequence(b, robot)
    assert seq.joints == again.joints == ("r_shoulder_pitch", "r_elbow")
    assert np.array_equal(seq.times, again.times) and np.array_equal(seq.poses, again.poses)
    assert seq.at(1.5).tolist() == [-1.0, -0.9]


@pytest.mark.parametrize("edit, needle", [
    (("t = 1.5", "t = 0.0"), "keyframe[1].t: 0 s is not after keyframe[0].t"),
    (("r_elbow = -0.9", "r_elbo = -0.9"), "keyframe[1].r_elbo: unknown joint"),
    (("r_elbow = -0.9", "r_elbow = -3.0"), "keyframe[1].r_elbow: -3 rad is outside the joint"),
    (("r_elbow = -0.9", "r_elbow = 'x'"), "keyframe[1].r_elbow: expected a number"),
    (("t = 3.0", "t = 1.6"), "would move at"),
    (('name = "wave"', 'name = "wave"\ninterpolation = "cubic"'), "interpolation: expected"),
    (('name = "wave"', 'name = "wave"\nloop = true'), "loop = true needs the last"),
    (("r_shoulder_pitch = -1.0\n", ""), "keyframe[1]: joint 'r_shoulder_pitch' missing"),
])
def test_bad_sequences_are_one_line_errors(tmp_path: Path, edit: tuple[str, str],
                                           needle: str, capsys: pytest.CaptureFixture[str]
                                           ) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(WAVE.replace(*edit, 1))
    with pytest.raises(ConfigError) as e:
        load_sequence(path, default_robot())
    assert needle in str(e.value) and str(path) in str(e.value), str(e.value)
    assert cli.main(["play", str(path)]) == 2  # refused before the bus opens
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and needle in err


def test_legs_cannot_be_layered_on_the_walk(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "kick.toml"
    path.write_text("[[keyframe]]\nt = 0.0\nr_knee = 0.3\n")
    assert cli.main(["walk", "--seconds", "0.2", "--keyframes", str(path)]) == 2
    assert "drives arms and extra joints only" in capsys.readouterr().err


# ------------------------------------------------------------------ layered on the walk


def test_arms_follow_the_keyframes_while_the_legs_walk(tmp_path: Path) -> None:
    robot = default_robot()
    keys = tmp_path / "wave.toml"
    keys.write_text(WAVE)
    plain, layered = tmp_path / "plain.take.jsonl", tmp_path / "layered.take.jsonl"
    common = ["walk", "--seconds", "3", "--no-balance", "--rate", "100"]
    assert cli.main([*common, "--record", str(plain)]) == 0
    assert cli.main([*common, "--keyframes", str(keys), "--record", str(layered)]) == 0
    a, b = read_take(plain), read_take(layered)
    walking = [i for i, s in enumerate(b.states) if s == "walking"]
    names = robot.joint_names
    legs = [i for i, n in enumerate(names) if "shoulder" not in n and "elbow" not in n]
    # Legs: the open-loop gait exactly, keyframes or not.
    assert np.array_equal(a.q[walking][:, legs], b.q[walking][:, legs])
    # Arms: the minimum-jerk profile at the gait's time (gait tick k runs at t = (k+1)/rate).
    seq = load_sequence(keys, robot)
    for n_walk, i in enumerate(walking):
        t = (n_walk + 1) / 100.0
        for col, joint in enumerate(seq.joints):
            k = 0 if t < 1.5 else 1
            s = min(max((t - seq.times[k]) / 1.5, 0.0), 1.0)
            want = seq.poses[k, col] + (seq.poses[k + 1, col] - seq.poses[k, col]) * (
                10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5)
            assert b.q[i, names.index(joint)] == pytest.approx(want, abs=1e-9), (t, joint)
    # The take replays with its keyframes.
    replay = tmp_path / "replay.take.jsonl"
    assert cli.main(["play", str(layered), "--record", str(replay)]) == 0
    assert np.max(np.abs(read_take(replay).q - b.q)) <= 1e-6


def test_a_sequence_plays_alone_and_ends_at_rest(tmp_path: Path) -> None:
    keys = tmp_path / "wave.toml"
    keys.write_text(WAVE)
    assert cli.main(["play", str(keys), "--record", str(tmp_path / "x.take.jsonl")]) == 2
    log = tmp_path / "alone.csv"
    assert cli.main(["play", str(keys), "--record", str(log)]) == 0
    table = read_table(log)
    moving = [k for k, s in enumerate(table.states) if s == "walking"]
    assert len(moving) == pytest.approx(3.0 * 200, abs=2)
    pitch = table.columns["cmd_r_shoulder_pitch"]
    assert pitch[moving].min() == pytest.approx(-1.0, abs=1e-3)
    assert table.states[-1] == "rest"


# ------------------------------------------------------------------ posing by hand


def ticks_of(robot: RobotConfig, joint: str, q: float) -> int:
    j = robot.joint(joint)
    return round(j.zero_ticks + j.sign * q * MODELS[robot.bus.model].ticks_per_rad)


def test_capture_by_hand_on_the_emulator(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                                         tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    """The arms go limp, the legs hold; each keyframe is what the hand put the arms at."""
    poses = [{"r_shoulder_pitch": -0.5, "r_elbow": -0.4, "l_shoulder_roll": 0.2},
             {"r_shoulder_pitch": -1.1, "r_elbow": -1.0, "l_shoulder_roll": 0.5}]
    arms = [j for j in robot.joint_names if "shoulder" in j or "elbow" in j]
    seen: dict[str, dict[str, int]] = {}
    answers = iter(["", "", "q"])
    per_rad = MODELS[robot.bus.model].ticks_per_rad

    def ask(prompt: str) -> str:
        n = int(prompt.split()[1].rstrip(":"))
        if n == 0:  # released: read the registers the way the test judges safety
            seen.update({j.name: emu.registers(j.servo_id) for j in robot.joints})
        if n < len(poses):
            for joint in arms:  # the hand moves every arm joint (torque off: goal follows)
                ticks = ticks_of(robot, joint, poses[n].get(joint, 0.0))
                emu.set_register(robot.joint(joint).servo_id, "goal_position", ticks)
                emu.set_register(robot.joint(joint).servo_id, "present_position", ticks)
        return next(answers)

    out = tmp_path / "by-hand.toml"
    args = cli.build_parser().parse_args(
        ["capture", "--robot", str(robot_toml), "--bus", emu.protocol, "--port", emu.port,
         "--limb", "arms", "--every", "2.0", "--out", str(out)])
    assert capture_cmd.run(args, ask=ask) == 0
    for j in robot.joints:
        regs = seen[j.name]
        if j.name in arms:
            assert regs["torque_enable"] == 0, j.name
        else:  # held where it was: torque on, goal at the present position
            assert regs["torque_enable"] == 1, j.name
            assert abs(regs["goal_position"] - regs["present_position"]) <= 1, j.name
    seq = load_sequence(out, robot)
    assert seq.joints == tuple(arms) and seq.times.tolist() == [0.0, 2.0]
    for k, pose in enumerate(poses):
        for joint in arms:
            want = (ticks_of(robot, joint, pose.get(joint, 0.0)) - robot.joint(joint)
                    .zero_ticks) * robot.joint(joint).sign / per_rad
            assert seq.poses[k, arms.index(joint)] == pytest.approx(want, abs=1e-9)
            assert math.isclose(want, pose.get(joint, 0.0), abs_tol=1.0 / per_rad)
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}  # all limp at the end
    assert "torque OFF on every servo" in capsys.readouterr().out


def test_panel_capture_on_the_emulator(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                                       tmp_path: Path) -> None:
    """The panel's studio: release the right arm, the hand moves it, capture, save."""
    from robot.panel.controller import BusSpec, LoopOptions, make_controller
    from robot.panel.studio import Studio

    robot = load_robot(robot_toml)
    controller = make_controller(robot, BusSpec(emu.protocol, port=emu.port),
                                 load_gait("walk").params,
                                 options=LoopOptions(rate_hz=50.0))
    studio = Studio(controller, takes_dir=tmp_path / "t", keys_dir=tmp_path / "k")
    arm = ("r_shoulder_pitch", "r_shoulder_roll", "r_elbow")
    try:
        with pytest.raises(ConfigError, match="limb 'tail': unknown; valid"):
            studio.release("tail")
        assert studio.release("right_arm")["capture_joints"] == list(arm)
        assert [emu.registers(robot.joint(j).servo_id)["torque_enable"] for j in arm] == [0] * 3
        assert emu.registers(robot.joint("l_elbow").servo_id)["torque_enable"] == 1
        for k, elbow in enumerate((-0.3, -1.2)):
            ticks = ticks_of(robot, "r_elbow", elbow)
            sid = robot.joint("r_elbow").servo_id
            emu.set_register(sid, "goal_position", ticks)
            emu.set_register(sid, "present_position", ticks)
            got = studio.capture()
            assert got["t"] == float(k) and got["pose"]["r_elbow"] == pytest.approx(
                elbow, abs=1.0 / MODELS[robot.bus.model].ticks_per_rad)
        path = Path(studio.save("reach"))
        seq = load_sequence(path, robot)
        assert seq.joints == arm and len(seq.times) == 2 and studio.sequences() == ["reach"]
    finally:
        controller.shutdown(timeout=5)
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}
