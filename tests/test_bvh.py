"""BVH export read back with bvhio (a BVH library from PyPI, not ours): the skeleton, the
frame count and time, each joint's rotation against the joint stream, and the joint
positions bvhio computes from the hierarchy against the robot's forward kinematics."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import bvhio
import numpy as np
import pytest

import robot.cli as cli
from robot.config.bundled import DEFAULT_ROBOT
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.gait.ik import arm_fk_local, leg_fk_full, shoulder_centre
from robot.motion.takes import read_take

FPS = 30.0


def quat(axis: str, deg: float) -> np.ndarray:
    """(w, x, y, z) of a rotation about a BVH axis."""
    h = math.radians(deg) / 2
    v = {"X": (1, 0, 0), "Y": (0, 1, 0), "Z": (0, 0, 1)}[axis]
    return np.array([math.cos(h), *(math.sin(h) * np.array(v))])


def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def bvh_of_robot(v: np.ndarray) -> np.ndarray:
    """REP-103 → BVH axes (X left, Y up, Z forward), written out independently."""
    return np.array([v[1], v[2], v[0]])


#: BVH joint → (axis, robot joint) per rotation, in the robot's composition order.
ROTATIONS = {
    "r_hip": (("Y", "r_hip_yaw"), ("Z", "r_hip_roll"), ("X", "r_hip_pitch")),
    "r_knee": (("X", "r_knee"),),
    "r_ankle": (("X", "r_ankle_pitch"), ("Z", "r_ankle_roll")),
    "l_hip": (("Y", "l_hip_yaw"), ("Z", "l_hip_roll"), ("X", "l_hip_pitch")),
    "l_knee": (("X", "l_knee"),),
    "l_ankle": (("X", "l_ankle_pitch"), ("Z", "l_ankle_roll")),
    "r_shoulder": (("X", "r_shoulder_pitch"), ("Z", "r_shoulder_roll")),
    "r_elbow": (("X", "r_elbow"),),
    "l_shoulder": (("X", "l_shoulder_pitch"), ("Z", "l_shoulder_roll")),
    "l_elbow": (("X", "l_elbow"),),
}


def test_gait_export_round_trips(tmp_path: Path) -> None:
    robot = load_robot(DEFAULT_ROBOT)
    out = tmp_path / "walk.bvh"
    assert cli.main(["export", "--gait", "walk", "--seconds", "2", "--out", str(out)]) == 0
    frames = int(2 * FPS) + 1
    raw = bvhio.readAsBvh(str(out))
    assert raw.FrameCount == frames and raw.FrameTime == pytest.approx(1 / FPS, abs=1e-6)
    joints = {j.Name: j for j, _, _ in raw.Root.layout()}
    assert set(joints) == {"pelvis", "chest", *ROTATIONS}
    # The joint stream the export must carry: the gait at constant parameters.
    _, qt = GaitEngine(robot, load_gait("walk").params).curves(np.arange(frames) / FPS)
    names = robot.joint_names
    for name, rots in ROTATIONS.items():
        for f in range(0, frames, 7):
            want = np.array([1.0, 0, 0, 0])
            for axis, joint in rots:
                want = qmul(want, quat(axis, math.degrees(qt[names.index(joint), f])))
            r = joints[name].Keyframes[f].Rotation
            got = np.array([r.w, r.x, r.y, r.z])
            assert min(np.abs(got - want).max(), np.abs(got + want).max()) < 1e-5, (name, f)
    # Positions as bvhio composes the hierarchy, against the robot's FK (pelvis frame).
    g = robot.geometry
    tree = bvhio.readAsHierarchy(str(out))
    for f in range(0, frames, 5):
        tree.loadPose(f)
        world = {j.Name: np.array(j.PositionWorld) for j, _, _ in tree.layout()}
        q = {n: float(qt[i, f]) for i, n in enumerate(names)}
        for side in ("r", "l"):
            leg = tuple(q[f"{side}_{n}"] for n in ("hip_yaw", "hip_roll", "hip_pitch", "knee",
                                                   "ankle_pitch", "ankle_roll"))
            knee, _ = leg_fk_full(dataclasses.replace(g, shin=0.0, ankle_height=0.0), side, leg)
            ankle, _ = leg_fk_full(dataclasses.replace(g, ankle_height=0.0), side, leg)
            for joint, p in ((f"{side}_knee", knee), (f"{side}_ankle", ankle)):
                rel = world[joint] - world["pelvis"]
                assert rel == pytest.approx(100 * bvh_of_robot(np.array(p)), abs=1e-3), joint
            arm = (q[f"{side}_shoulder_pitch"], q[f"{side}_shoulder_roll"], q[f"{side}_elbow"])
            elbow = np.add(shoulder_centre(g, side),
                           arm_fk_local(dataclasses.replace(g, forearm=0.0), arm))
            rel = world[f"{side}_elbow"] - world["pelvis"]
            assert rel == pytest.approx(100 * bvh_of_robot(elbow), abs=1e-3)
        # The lower ankle is ankle_height above the ground (y = 0).
        assert min(world["r_ankle"][1], world["l_ankle"][1]) == pytest.approx(
            100 * g.ankle_height, abs=1e-3)
    tree.loadPose(frames - 1)
    assert np.array(tree.PositionWorld)[2] > 10.0  # walked forward (+Z) over 2 s [cm]


def test_take_export_carries_the_recorded_stream(tmp_path: Path) -> None:
    take, out = tmp_path / "t.take.jsonl", tmp_path / "t.bvh"
    assert cli.main(["walk", "--seconds", "1", "--set", "turn=0.2", "--record", str(take)]) == 0
    assert cli.main(["export", "--take", str(take), "--fps", "50", "--units", "m",
                     "--out", str(out)]) == 0
    rec = read_take(take)
    raw = bvhio.readAsBvh(str(out))
    step = int(rec.header.rate_hz / 50)  # 200 Hz ticks → every 4th is a frame
    assert raw.FrameCount == (len(rec.t) - 1) // step + 1
    joints = {j.Name: j for j, _, _ in raw.Root.layout()}
    names = rec.header.joints
    for f in range(0, raw.FrameCount, 11):
        angle = rec.q[f * step, names.index("r_hip_yaw")]
        r = joints["r_hip"].Keyframes[f].Rotation
        # A yaw-only check needs the other two hip angles: compose all three.
        want = qmul(qmul(quat("Y", math.degrees(angle)),
                         quat("Z", math.degrees(rec.q[f * step, names.index("r_hip_roll")]))),
                    quat("X", math.degrees(rec.q[f * step, names.index("r_hip_pitch")])))
        got = np.array([r.w, r.x, r.y, r.z])
        assert min(np.abs(got - want).max(), np.abs(got + want).max()) < 1e-5, f
    offsets = {j.Name: np.array(j.Offset) for j, _, _ in raw.Root.layout()}
    assert offsets["r_knee"] == pytest.approx([0, -load_robot().geometry.thigh, 0], abs=1e-6)


def test_export_refuses_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["export", "--out", str(tmp_path / "x.txt")]) == 2
    assert "expected a .bvh" in capsys.readouterr().err
    assert cli.main(["export", "--take", str(tmp_path / "none.take.jsonl"),
                     "--out", str(tmp_path / "x.bvh")]) == 2
    assert "does not exist" in capsys.readouterr().err
