"""Previs on an imported robot (issue 31): `biped export` builds the skeleton from the
robot's own model, judged by independent readers: bvhio reads the BVH back, MuJoCo
compiles the vendor's original file (tests/kit_models.py). Every joint's offset is the
model's (MuJoCo's joint anchors at the zero pose) within 1e-6 m; at every frame the
joints stand where MuJoCo puts the anchors at that frame's angles (`biped curves
--model-angles`), and at random angles every joint and chain end where MuJoCo has it
(composed from bvhio's parse: each channel's sign counts); export → import gives back
the gait's angles as the box robot's round trip does (tests/test_import.py: 1e-4 rad);
the panel's stick figure draws each hinge on MuJoCo's axis and the sole where MuJoCo's
foot has it; `biped render` films the model."""

from __future__ import annotations

import csv
from pathlib import Path

import bvhio
import mujoco
import numpy as np
import pytest
from kit_models import KITS, without_meshes

import robot.cli as cli
from robot.config.bundled import resolve_robot_path
from robot.config.gait_file import load_gait
from robot.config.joint_names import LEG_NAMES
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.motion.takes import read_take
from robot.panel.figure import stick_figure, views
from robot.previs.bvh import write_bvh
from sim.mujoco.render import ClipSpec, render_walk

FPS, SECONDS = 30, 1


class Anchors:
    """MuJoCo on the original file: each joint's anchor and axis [m] in the robot frame
    (the file's root frame, x forward, z up, as the [model] axes say) from the pelvis, the
    midpoint of the two hip pitch axes at the zero pose (docs/robots.md)."""

    def __init__(self, kit: str) -> None:
        self.robot = load_robot(kit)
        self.model = without_meshes(KITS[kit])
        self.data = mujoco.MjData(self.model)
        assert np.allclose(self.robot.body.axes, np.eye(3))   # both kits: REP-103 roots
        self.root = self.model.body(self.robot.body.tree.links[0].name).id
        self.joint = {j.name: j.model_joint for j in self.robot.joints}
        self.pelvis = np.zeros(3)
        self.zero()
        hips = [self.anchor(n) for n in ("r_hip_pitch", "l_hip_pitch")]
        self.pelvis = (hips[0] + hips[1]) / 2 * np.array([1.0, 0.0, 1.0])  # fixed on the root

    def at(self, model_angles: dict[str, float]) -> None:
        self.data.qpos[:] = self.model.qpos0
        for name, v in model_angles.items():
            self.data.qpos[self.model.joint(name).qposadr[0]] = v
        mujoco.mj_kinematics(self.model, self.data)
        self.r0 = self.data.xmat[self.root].reshape(3, 3)
        self.p0 = self.data.xpos[self.root]

    def zero(self) -> None:
        self.at({j.model_joint: j.model_offset for j in self.robot.joints})

    def local(self, world: np.ndarray) -> np.ndarray:
        return self.r0.T @ (world - self.p0)

    def anchor(self, joint: str) -> np.ndarray:
        """The project joint's anchor [m] from the pelvis."""
        return self.local(self.data.xanchor[self.model.joint(self.joint[joint]).id]) - self.pelvis

    def axis(self, joint: str) -> np.ndarray:
        return self.r0.T @ self.data.xaxis[self.model.joint(self.joint[joint]).id]

    def parent_joint(self, joint: str) -> str | None:
        """The project joint of the nearest hinge above ``joint``'s body (None: the root)."""
        by_model = {v: k for k, v in self.joint.items()}
        b = self.model.body_parentid[self.model.jnt_bodyid[self.model.joint(self.joint[joint]).id]]
        while b > 0:
            for j in range(self.model.body_jntadr[b], self.model.body_jntadr[b] + self.model.body_jntnum[b]):
                if self.model.joint(j).name in by_model:
                    return by_model[self.model.joint(j).name]
            b = self.model.body_parentid[b]
        return None


def bvh_to_robot(v: object) -> np.ndarray:
    """A bvhio vector [cm] (X left, Y up, Z forward) in the robot frame [m]."""
    x, y, z = (float(getattr(v, a)) for a in "xyz")
    return np.array([z, x, y]) / 100.0


@pytest.mark.parametrize("kit", KITS)
def test_the_bvh_skeleton_is_the_model_s(kit: str, tmp_path: Path) -> None:
    anim, curves = tmp_path / "walk.bvh", tmp_path / "walk.csv"
    assert cli.main(["export", "--robot", kit, "--seconds", str(SECONDS), "--fps", str(FPS),
                     "--out", str(anim)]) == 0
    assert cli.main(["curves", "--robot", kit, "--seconds", str(SECONDS), "--rate", str(FPS),
                     "--model-angles", "--out", str(curves)]) == 0
    mj = Anchors(kit)
    mj.zero()
    joints = {j.Name: j for j, _, _ in bvhio.readAsBvh(str(anim)).Root.layout()}
    parent = {c.Name: j.Name for j in joints.values() for c in j.Children}
    assert set(joints) == {"pelvis", *mj.robot.joint_names}
    worst = 0.0
    for name in mj.robot.joint_names:
        above = mj.parent_joint(name)
        assert parent[name] == (above or "pelvis"), name
        want = mj.anchor(name) - (mj.anchor(above) if above else 0.0)
        worst = max(worst, float(np.abs(bvh_to_robot(joints[name].Offset) - want).max()))
    assert worst < 1e-6, worst
    # every frame: the joints where MuJoCo puts the anchors at that frame's model angles
    with curves.open(newline="") as f:
        rows = list(csv.DictReader(f))
    hierarchy = bvhio.readAsHierarchy(str(anim))
    worst = 0.0
    for k in range(0, len(rows), 5):
        mj.at({m: float(rows[k][m]) for m in mj.joint.values()})
        hierarchy.loadPose(k)
        placed = {j.Name: bvh_to_robot(j.PositionWorld) for j, _, _ in hierarchy.layout()}
        for name in mj.robot.joint_names:
            got = placed[name] - placed["pelvis"]
            worst = max(worst, float(np.abs(got - mj.anchor(name)).max()))
    assert worst < 1e-6, worst


def _quat(q: object) -> np.ndarray:
    """A bvhio (glm) quaternion in BVH axes as a rotation matrix in the robot's axes."""
    w, x, y, z = (float(getattr(q, a)) for a in "wxyz")
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    p = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])  # BVH (X, Y, Z) → (z, x, y)
    return p @ r @ p.T


@pytest.mark.parametrize("kit", KITS)
def test_every_joint_turns_the_model_s_way(kit: str, tmp_path: Path) -> None:
    """Random angles in every joint's range, written as BVH, composed again from bvhio's
    parse (offsets, end sites, each frame's rotations): each joint and each chain end (the
    sole frame, else the link's first frame: the exporter's marker body in the file, else
    its centre of mass: MuJoCo's xipos) where MuJoCo puts it."""
    mj = Anchors(kit)
    robot = mj.robot
    rng = np.random.default_rng(3)
    q = np.array([[rng.uniform(max(j.min_rad, -1.0), min(j.max_rad, 1.0)) for j in robot.joints]
                  for _ in range(6)])
    write_bvh(tmp_path / "r.bvh", robot, q, 0.1)
    layout = bvhio.readAsBvh(str(tmp_path / "r.bvh")).Root.layout()
    parent = {c.Name: j.Name for j, _, _ in layout for c in j.Children}
    soles = {link.name: np.array(f.pos) for link in robot.body.tree.links
             for f in link.frames if f.name in ("r_sole", "l_sole")}
    frames = {link.name: [f.name for f in link.frames] for link in robot.body.tree.links}
    worst = 0.0
    for k, row in enumerate(q):
        mj.at({j.model_joint: j.model_sign * v + j.model_offset
               for j, v in zip(robot.joints, row, strict=True)})
        pos, rot = {"pelvis": np.zeros(3)}, {"pelvis": np.eye(3)}
        for joint, _, _ in layout[1:]:
            up = parent[joint.Name]
            pos[joint.Name] = pos[up] + rot[up] @ bvh_to_robot(joint.Offset)
            rot[joint.Name] = rot[up] @ _quat(joint.Keyframes[k].Rotation)
            worst = max(worst, float(np.abs(pos[joint.Name] - mj.anchor(joint.Name)).max()))
            if joint.Children:
                continue
            end = pos[joint.Name] + rot[joint.Name] @ bvh_to_robot(joint.EndSite)
            b = mj.model.jnt_bodyid[mj.model.joint(mj.joint[joint.Name]).id]
            name = mj.model.body(b).name
            marks = frames.get(name, [])   # its first frame, an exporter's marker body
            want = (mj.data.xpos[b] + mj.data.xmat[b].reshape(3, 3) @ soles[name]
                    if name in soles else mj.data.xpos[mj.model.body(marks[0]).id] if marks
                    else mj.data.xipos[b])
            worst = max(worst, float(np.abs(end - (mj.local(want) - mj.pelvis)).max()))
    assert worst < 1e-6, worst


@pytest.mark.parametrize("kit, suffix", [("robotis-op3", ".bvh"), ("robotis-op3", ".glb"),
                                         ("open-duck-mini-v2", ".bvh")])
def test_export_then_import_round_trips_on_the_model(kit: str, suffix: str,
                                                     tmp_path: Path) -> None:
    """The skeleton round trip, on a walk within the robot's joint speeds: the Duck's own
    [gait] (vM 0.6) asks its knees 1.7x their speed, which import clamps as it must, so
    its case walks a copy of the Duck at the preset's vM 0.3 (0.86x the knee's speed)."""
    anim, out = tmp_path / f"walk{suffix}", tmp_path / "walk.take.jsonl"
    name = kit
    if kit == "open-duck-mini-v2":
        text = resolve_robot_path(kit).read_text()
        assert "vM = 0.6" in text
        name = str(tmp_path / f"{kit}.toml")
        Path(name).write_text(text.replace("vM = 0.6", "vM = 0.3"))
    assert cli.main(["export", "--robot", name, "--seconds", "2", "--fps", "30",
                     "--out", str(anim)]) == 0
    assert cli.main(["import", str(anim), "--robot", name, "--out", str(out)]) == 0
    robot = load_robot(name)
    params = load_gait("walk").for_robot(robot)   # what export walks: the robot's [gait]
    _, qt = GaitEngine(robot, params).curves(np.arange(61) / 30.0, with_channels=False)
    take = read_take(out)
    assert take.header.rate_hz == 210.0 and take.header.joints == robot.joint_names
    assert np.abs(take.q[::7] - qt.T).max() < 1e-4


def test_the_stick_figure_is_drawn_on_the_model(tmp_path: Path) -> None:
    mj = Anchors("robotis-op3")
    robot = mj.robot
    rng = np.random.default_rng(7)
    soles = {f.name: (link.name, np.array(f.pos)) for link in robot.body.tree.links
             for f in link.frames if f.name in ("r_sole", "l_sole")}
    for _ in range(5):
        q = [float(rng.uniform(max(j.min_rad, -0.6), min(j.max_rad, 0.6))) for j in robot.joints]
        lines = stick_figure(robot, q)
        mj.at({j.model_joint: j.model_sign * v + j.model_offset
               for j, v in zip(robot.joints, q, strict=True)})
        for side in "rl":
            chain = [n for n in robot.joint_names if n in LEG_NAMES and n[0] == side]
            pts = np.array(lines[f"{side}_leg"])
            for point, name in zip(pts[:len(chain)], chain, strict=True):  # on its axis
                off = point - mj.anchor(name)
                u = mj.axis(name)
                assert np.linalg.norm(off - u * (off @ u)) < 1e-9, name
            body, local = soles[f"{side}_sole"]
            b = mj.model.body(body).id
            sole = mj.local(mj.data.xpos[b] + mj.data.xmat[b].reshape(3, 3) @ local) - mj.pelvis
            assert np.abs(pts[len(chain)] - sole).max() < 1e-9
            assert np.abs(pts[-1] - sole).max() < 1e-9      # toe, heel, back to the sole
    drawn = views(robot, [0.0] * len(robot.joints))
    assert set(drawn["side"]) == {"r_leg", "l_leg", "r_arm", "l_arm", "head", "torso"}
    assert min(p[1] for n in ("r_leg", "l_leg") for p in drawn["side"][n]) == 0.0


def test_render_films_the_imported_model(tmp_path: Path) -> None:
    robot = load_robot("robotis-op3")
    spec = ClipSpec(seconds=0.6, width=96, height=64, fps=10)
    res = render_walk(robot, load_gait("walk").params, tmp_path / "op3.gif", spec=spec,
                      progress=False)
    assert res.frames == 6 and not res.fell and res.path.stat().st_size > 1000
