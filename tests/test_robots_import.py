"""`biped robots import`: the published ROBOTIS OP3 and Open Duck Mini v2 models and an
onshape-to-robot-style URDF written for the tests (tests/cad_robot.py) become robot files
whose joints are named, signed and zeroed as the project's convention says, and every
file it cannot take is one line, exit 2, and nothing written.

Oracles: the vendor's own joint names and ids (ROBOTIS's OP3.robot, written out here),
MuJoCo's FK of the ORIGINAL file (the axis of each joint in the world, the anchors), and
the numbers tests/cad_robot.py was written with; never the importer's own kinematics.
"""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

import mujoco
import numpy as np
import pytest

import robot.cli as cli
from robot.config.robot_file import load_robot
from tests import cad_robot

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared" / "robots"
OP3 = SHARED / "robotis_op3" / "op3.xml"
DUCK = SHARED / "open_duck_mini_v2" / "robot.xml"
OP3_MAP = REPO / "robot" / "configs" / "import" / "robotis-op3.toml"
#: ROBOTIS's names → the project's, and ROBOTIS's ids (op3_manager/config/OP3.robot).
OP3_JOINTS = {
    "r_sho_pitch": ("r_shoulder_pitch", 1), "l_sho_pitch": ("l_shoulder_pitch", 2),
    "r_sho_roll": ("r_shoulder_roll", 3), "l_sho_roll": ("l_shoulder_roll", 4),
    "r_el": ("r_elbow", 5), "l_el": ("l_elbow", 6), "r_hip_yaw": ("r_hip_yaw", 7),
    "l_hip_yaw": ("l_hip_yaw", 8), "r_hip_roll": ("r_hip_roll", 9),
    "l_hip_roll": ("l_hip_roll", 10), "r_hip_pitch": ("r_hip_pitch", 11),
    "l_hip_pitch": ("l_hip_pitch", 12), "r_knee": ("r_knee", 13), "l_knee": ("l_knee", 14),
    "r_ank_pitch": ("r_ankle_pitch", 15), "l_ank_pitch": ("l_ankle_pitch", 16),
    "r_ank_roll": ("r_ankle_roll", 17), "l_ank_roll": ("l_ankle_roll", 18),
    "head_pan": ("head_pan", 19), "head_tilt": ("head_tilt", 20)}
#: The project's axis of each role (docs/robots.md: REP-103, right-hand rule).
AXIS = {"hip_yaw": (0, 0, 1), "hip_roll": (1, 0, 0), "hip_pitch": (0, 1, 0), "knee": (0, 1, 0),
        "ankle_pitch": (0, 1, 0), "ankle_roll": (1, 0, 0), "shoulder_pitch": (0, 1, 0),
        "shoulder_roll": (1, 0, 0)}


def without_meshes(path: Path) -> mujoco.MjModel:
    """The original file in MuJoCo with its (missing) meshes and mesh geoms removed."""
    xml = path.read_text()
    xml = re.sub(r"<mesh [^>]*/>", "", xml)
    xml = re.sub(r"<geom[^>]*mesh=\"[^\"]*\"[^>]*/>", "", xml)
    xml = re.sub(r'meshdir="[^"]*"', "", xml)
    return mujoco.MjModel.from_xml_string(xml)


def world_axes(model: mujoco.MjModel) -> dict[str, np.ndarray]:
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return {model.joint(j).name: np.array(data.xaxis[j]) for j in range(model.njnt)
            if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE}


def one_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    return err


def test_op3_joints_are_the_vendors_with_signs_from_their_axes(tmp_path: Path) -> None:
    out = tmp_path / "op3.toml"
    assert cli.main(["robots", "import", str(OP3), "--missing-meshes", "box",
                     "--map", str(OP3_MAP), "--out", str(out)]) == 0
    robot = load_robot(out)
    axes = world_axes(without_meshes(OP3))
    assert {j.model_joint: (j.name, j.servo_id) for j in robot.joints} == OP3_JOINTS
    for j in robot.joints:
        role = j.name[2:]
        if role in AXIS:   # the model's axis points along the project's: +1, against: -1
            assert j.model_sign == round(float(axes[j.model_joint] @ AXIS[role])), j.name
        assert j.sign == j.model_sign and j.zero_ticks == 2048 + round(j.model_offset * 4096
                                                                         / (2 * math.pi))
    # the arms hang at the project's zero: the model's T-pose is +-90 deg of shoulder roll
    assert robot.joint("l_shoulder_roll").model_offset == pytest.approx(math.pi / 2, abs=2e-3)
    assert robot.joint("r_shoulder_roll").model_offset == pytest.approx(-math.pi / 2, abs=2e-3)
    assert robot.bus.baud == 2_000_000 and robot.bus.model == "XM430-W350"
    # limits: the vendor's table, turned into the project's convention (right knee: the
    # table's -135..+148 deg with CW positive is the model's -148..135 deg, sign -1)
    knee = robot.joint("r_knee")
    assert (knee.min_rad, knee.max_rad) == pytest.approx(np.radians([-135, 148]), abs=1e-6)


def test_op3_without_meshes_is_refused_naming_the_mesh(tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "op3.toml"
    assert cli.main(["robots", "import", str(OP3), "--out", str(out)]) == 2
    line = one_line(capsys)
    assert "collision mesh 'bodyc'" in line and "simplified_convex/body.stl" in line
    assert "--missing-meshes box" in line and not out.exists()


def test_mjcf_of_an_imported_robot_has_the_models_mass_and_legs(tmp_path: Path) -> None:
    out = tmp_path / "op3.toml"
    assert cli.main(["robots", "import", str(OP3), "--missing-meshes", "box",
                     "--map", str(OP3_MAP), "--out", str(out)]) == 0
    assert cli.main(["mjcf", "--robot", str(out), "--out", str(tmp_path / "mj")]) == 0
    ours = mujoco.MjModel.from_xml_path(str(tmp_path / "mj" / "scene.xml"))
    theirs = without_meshes(OP3)
    torso = ours.body("torso").id
    assert ours.body_subtreemass[torso] == pytest.approx(theirs.body_subtreemass[1], rel=1e-9)

    def anchors(model: mujoco.MjModel, names: tuple[str, ...]) -> list[float]:
        data = mujoco.MjData(model)
        data.qpos[:] = model.qpos0      # each at the model's own zero
        mujoco.mj_kinematics(model, data)
        pts = [data.xanchor[model.joint(n).id] for n in names]
        return [float(np.linalg.norm(b - a)) for a, b in zip(pts, pts[1:], strict=False)]
    for side in "rl":
        theirs_len = anchors(theirs, (f"{side}_hip_pitch", f"{side}_knee", f"{side}_ank_pitch"))
        ours_len = anchors(ours, (f"{side}_hip_pitch", f"{side}_knee", f"{side}_ankle_pitch"))
        assert ours_len == pytest.approx(theirs_len, abs=1e-9)


def test_the_cad_urdf_is_measured_as_it_was_written(tmp_path: Path) -> None:
    urdf, meshes = cad_robot.write(tmp_path)
    out = tmp_path / "cad.toml"
    assert cli.main(["robots", "import", str(urdf), "--mesh-dir", str(meshes),
                     "--out", str(out)]) == 0
    robot = load_robot(out)
    assert robot.body is not None
    right, left = robot.body.legs
    for leg, s in ((right, -1.0), (left, 1.0)):
        assert leg.thigh == pytest.approx(cad_robot.THIGH, abs=1e-9)
        assert leg.shin == pytest.approx(cad_robot.SHIN, abs=1e-9)
        assert leg.roll_drop == pytest.approx(cad_robot.ROLL_DROP, abs=1e-9)
        assert leg.lateral == pytest.approx(s * cad_robot.LATERAL, abs=1e-9)
        assert leg.ankle_drop == pytest.approx(cad_robot.ANKLE_DROP, abs=1e-9)
        assert leg.yaw_axis is not None
        assert leg.yaw_axis[0] - leg.hip[0] == pytest.approx(cad_robot.YAW_AHEAD, abs=1e-9)
        assert leg.sole[2] == pytest.approx(-cad_robot.SOLE_BELOW, abs=1e-6)
    # the model's zero pose, in the project's angles (model angle 0 = sign q + offset):
    # the thigh leaning forward by BEND (hip pitch -BEND), the knee bent 2 BEND, the
    # ankle -BEND (the foot flat)
    for side in "rl":
        for part, want in (("hip_pitch", -1), ("knee", 2), ("ankle_pitch", -1)):
            j = robot.joint(f"{side}_{part}")
            assert -j.model_sign * j.model_offset == pytest.approx(want * cad_robot.BEND, abs=1e-9)
    g = robot.geometry
    assert (g.foot_length, g.foot_width) == pytest.approx(cad_robot.FOOT[:2], abs=1e-6)
    assert g.foot_forward == pytest.approx(cad_robot.FOOT_AHEAD, abs=1e-6)
    data = tomllib.loads(out.read_text())
    assert "mass" not in data and data["model"]["links"][0]["name"] == "base_link"


@pytest.mark.parametrize("case", ["xacro", "prismatic", "mesh", "inertia", "layout", "two roles",
                                  "format"])
def test_a_model_it_cannot_take_is_one_line_and_nothing_written(
        case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    urdf, meshes = cad_robot.write(tmp_path)
    text = urdf.read_text()
    path, want = urdf, ""
    if case == "xacro":
        path = tmp_path / "robot.urdf.xacro"
        path.write_text(text.replace('<robot name="cad_robot">', '<robot name="cad_robot" '
                        'xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:include '
                        'filename="$(find cad_robot)/legs.xacro"/>'))
        want = "xacro"
    elif case == "prismatic":
        path.write_text(text.replace('name="left_knee" type="revolute"', 'name="left_knee" '
                                     'type="prismatic"'))
        want = "left_knee"
    elif case == "mesh":
        (meshes / "cad_robot" / "assets" / "Foot_Sole.STL").unlink()
        want = "Foot_Sole.STL"
    elif case == "inertia":
        path.write_text(text.replace('ixx="0.0001', 'ixx="-0.0001', 1))
        want = "inertia"
    elif case == "layout":   # a knee that turns about x: no leg pattern fits
        path.write_text(re.sub(r'(name="left_knee".*?<axis xyz=")0 -1 0', r"\g<1>1 0 0", text,
                               flags=re.S))
        want = "axes"
    elif case == "two roles":   # the ankle roll turned into a fourth pitch joint
        path.write_text(re.sub(r'(name="left_ankle_roll".*?<axis xyz=")1 0 0', r"\g<1>0 1 0",
                               text, flags=re.S))
        want = "4 joints turn about y (left_hip_pitch, left_knee, left_ankle_pitch, left_ankle_roll)"
    else:
        path = tmp_path / "robot.dae"
        path.write_text("<COLLADA/>")
        want = "unknown model format"
    out = tmp_path / "out.toml"
    assert cli.main(["robots", "import", str(path), "--mesh-dir", str(meshes),
                     "--out", str(out)]) == 2
    assert want in one_line(capsys)
    assert not out.exists()
