"""The physics check `biped play` runs on the sim: the support margin's geometry against
hand-worked squares, a gentle arms-only show that stays up with its centre of mass inside
the support polygon, a deep lean that falls after it starts, and --balance correcting the
legs while the arms play as authored."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import robot.cli as cli
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.motion.takes import read_take
from sim.mujoco.show_watch import hull, margin

FPS = 30.0


def test_margin_of_a_unit_square_by_hand() -> None:
    square = hull(np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5], [0.2, 0.9]], float))
    assert len(square) == 4                      # inner points are not on the hull
    assert margin(np.array([0.5, 0.5]), square) == pytest.approx(0.5)
    assert margin(np.array([0.9, 0.3]), square) == pytest.approx(0.1)
    assert margin(np.array([1.3, 0.5]), square) == pytest.approx(-0.3)
    assert margin(np.array([2.0, 2.0]), square) == pytest.approx(-math.sqrt(2))
    assert math.isnan(margin(np.array([0.0, 0.0]), hull(np.array([[0, 0], [1, 1.0]]))))


def _bvh(path: Path, frames: int, hip_deg: list[float], shoulder_deg: list[float]) -> None:
    """Our skeleton's names: both hips' pitch (Xrotation) and both shoulders' pitch."""
    def joint(name: str, off: str, end: str) -> list[str]:
        return [f"JOINT {name}", "{", f"OFFSET {off}", "CHANNELS 3 Zrotation Xrotation Yrotation",
                "End Site", "{", f"OFFSET {end}", "}", "}"]
    lines = ["HIERARCHY", "ROOT pelvis", "{", "OFFSET 0 0 0",
             "CHANNELS 6 Xposition Yposition Zposition Yrotation Zrotation Xrotation"]
    lines += joint("r_hip", "-5 0 0", "0 -40 0") + joint("l_hip", "5 0 0", "0 -40 0")
    lines += ["JOINT chest", "{", "OFFSET 0 30 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
    lines += joint("r_shoulder", "-10 0 0", "0 -20 0") + joint("l_shoulder", "10 0 0", "0 -20 0")
    lines += ["}", "}", "MOTION", f"Frames: {frames}", f"Frame Time: {1 / FPS:.6f}"]
    for k in range(frames):
        h, s = hip_deg[k], shoulder_deg[k]
        lines.append(f"0 45 0 0 0 0 0 {h} 0 0 {h} 0 0 0 0 0 {s} 0 0 {s} 0")
    path.write_text("\n".join(lines) + "\n")


def _map(path: Path, joints: list[tuple[str, str]]) -> None:
    """Each joint at the walk's standing angle when its bone is at rest (the offset)."""
    robot = load_robot()
    stand = GaitEngine(robot, load_gait("walk").params).start_pose()
    path.write_text("".join(f'[joints.{j}]\nbone = "{b}"\naxis = "y"\n'
                            f"offset = {stand[robot.joint_names.index(j)]!r}\n"
                            for j, b in joints))


ARMS = [("r_shoulder_pitch", "r_shoulder"), ("l_shoulder_pitch", "l_shoulder")]


def _import(tmp_path: Path, hips: list[float], shoulders: list[float],
            joints: list[tuple[str, str]]) -> Path:
    src, bones, out = tmp_path / "show.bvh", tmp_path / "map.toml", tmp_path / "show.take.jsonl"
    _bvh(src, len(hips), hips, shoulders)
    _map(bones, joints)
    assert cli.main(["import", str(src), "--map", str(bones), "--out", str(out)]) == 0
    return out


def test_a_gentle_arm_show_stays_up(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    n = int(3 * FPS)
    arms = [-40.0 * math.sin(math.pi * k / n) ** 2 for k in range(n)]
    take = _import(tmp_path, [0.0] * n, arms, ARMS)
    capsys.readouterr()
    plot = tmp_path / "check.png"
    assert cli.main(["play", str(take), "--json", "--check-plot", str(plot)]) == 0
    physics = json.loads(capsys.readouterr().out)["physics"]
    assert physics["fell"] is False and physics["fell_at_s"] is None
    assert physics["min_support_margin_m"] > 0.0 and physics["outside_support_s"] == 0.0
    joints = {j["joint"]: j for j in physics["joints"]}
    robot = load_robot()
    assert set(joints) == set(robot.joint_names)
    for j in joints.values():   # headroom is what is left of the peak, and peaks are real
        assert 0.0 <= j["peak_pct"] <= 100.0 + 1e-9
        assert j["headroom_pct"] == pytest.approx(100.0 - j["peak_pct"])
        assert j["peak_nm"] == pytest.approx(
            j["peak_pct"] / 100 * robot.servo(robot.joint(j["joint"])).stall_torque)
        assert j["temp_headroom_k"] == pytest.approx(70.0 - j["peak_c"])
    # Standing still, the knees carry more than the elbows.
    assert joints["r_knee"]["mean_pct"] > joints["r_elbow"]["mean_pct"]
    assert plot.stat().st_size > 10_000


def test_a_deep_lean_falls_after_it_starts(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    still, lean = int(1.0 * FPS), int(2.0 * FPS)
    hips = [0.0] * still + [-85.0 * min(1.0, k / 12) for k in range(lean)]
    take = _import(tmp_path, hips, [0.0] * len(hips),
                   [("r_hip_pitch", "r_hip"), ("l_hip_pitch", "l_hip")])
    capsys.readouterr()
    assert cli.main(["play", str(take)]) == 1        # the show did not hold up
    said = capsys.readouterr().out
    fell = float(said.split("FELL at t=")[1].split(" s")[0])
    assert 1.0 < fell < 3.0, said


def test_balance_corrects_the_legs_and_leaves_the_arms(tmp_path: Path) -> None:
    n = int(2 * FPS)
    arms = [-60.0 * math.sin(math.pi * k / n) ** 2 for k in range(n)]
    take_path = _import(tmp_path, [0.0] * n, arms, ARMS)
    take = read_take(take_path)
    record = tmp_path / "run.csv"
    assert cli.main(["play", str(take_path), "--balance", "--record", str(record)]) == 0
    rows = np.genfromtxt(record, delimiter=",", names=True, dtype=None, encoding="utf-8")
    show = rows[rows["state"] == "walking"]
    names = take.header.joints
    cmd = np.column_stack([show[f"cmd_{j}"] for j in names])
    arm = [names.index(j) for j, _ in ARMS]
    legs = [names.index(j) for j in ("r_hip_pitch", "r_ankle_pitch", "l_ankle_pitch")]
    assert np.abs(cmd[:, arm] - take.q[1:, arm]).max() < 1e-6
    assert np.abs(cmd[:, legs] - take.q[1:, legs]).max() > 1e-4
