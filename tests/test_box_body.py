"""The box model as a body tree (robot/body/boxes.py) simulates exactly the robot the MJCF
writer built straight from the robot file before (issue 31: one body description, two
sources): for every bundled box robot, the 5-DoF one with mixed servos and a head
(tests/five_dof.py), the one with extra joints (tests/extra_robot.py) and the servo zoo's
robots (tests/zoo_robots.py: other servo sizes), every array of the compiled mjModel is
the same to the last bit.

Oracle: tests/box_mjcf_before.py, the old writer kept as it was (default classes for the
joint groups, capsules by ``fromto``, ``diaginertia`` boxes, written element by element
from ``Geometry`` and ``Masses``); it shares with the code under test only the robot file,
the extra joints' layout, the servo law and the scene, never the body tree or the writer.
"""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

from pathlib import Path  # noqa: E402

import box_mjcf_before  # noqa: E402
import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from extra_robot import write_extra_robot  # noqa: E402
from five_dof import five_dof_robot  # noqa: E402
from zoo_robots import VARIANTS, robot_file  # noqa: E402

from robot.cli import main  # noqa: E402
from robot.config.body_tree import robot_tree  # noqa: E402
from robot.config.bundled import ROBOTS_DIR  # noqa: E402
from robot.config.robot import RobotConfig  # noqa: E402
from robot.config.robot_file import load_robot  # noqa: E402
from sim.mujoco.mjcf import ROBOT_FILE, build_mjcf, scene_xml, standing_qpos  # noqa: E402

BUNDLED = sorted(p.stem for p in ROBOTS_DIR.glob("*.toml"))
BOXES = [n for n in BUNDLED if load_robot(ROBOTS_DIR / f"{n}.toml").body is None]
IMPORTED = [n for n in BUNDLED if n not in BOXES]


def old_model(robot: RobotConfig) -> mujoco.MjModel:
    """The robot as the old writer built it, home keyframe included (sim/mujoco/mjcf.py's
    recipe: the rest pose and fixed joints, standing on the lowest sole point)."""
    scene = scene_xml(robot)
    bare = mujoco.MjModel.from_xml_string(
        scene, {ROBOT_FILE: box_mjcf_before.robot_xml(robot).encode()})
    fixed = {j.name: j.fixed_rad for j in robot.joints if j.fixed_rad is not None}
    home = standing_qpos(bare, {**robot.rest, **fixed})
    ctrl = home[bare.jnt_qposadr[bare.actuator_trnid[:, 0]]]
    xml = box_mjcf_before.robot_xml(robot, home=home, ctrl=ctrl)
    return mujoco.MjModel.from_xml_string(scene, {ROBOT_FILE: xml.encode()})


def arrays(model: mujoco.MjModel) -> dict[str, bytes]:
    """Every array of ``model`` and of its options, as raw bytes (so -0.0 differs from
    0.0), and the names."""
    out = {"names": bytes(model.names)}
    for owner, prefix in ((model, ""), (model.opt, "opt.")):
        for key in dir(owner):
            value = getattr(owner, key) if not key.startswith("_") else None
            if isinstance(value, np.ndarray):
                out[prefix + key] = value.dtype.str.encode() + repr(value.shape).encode() + value.tobytes()
            elif isinstance(value, (int, float)) and not isinstance(value, bool):
                out[prefix + key] = repr(value).encode()
    return out


def assert_same(new: mujoco.MjModel, old: mujoco.MjModel) -> None:
    a, b = arrays(new), arrays(old)
    assert sorted(a) == sorted(b)
    differ = [k for k in a if a[k] != b[k]]
    assert differ == []


def _robots(tmp: Path) -> dict[str, RobotConfig]:
    out = {n: load_robot(ROBOTS_DIR / f"{n}.toml") for n in BOXES}
    out["five_dof"] = five_dof_robot()
    out["extras"] = load_robot(write_extra_robot(tmp))
    for key, v in VARIANTS.items():
        out[key] = load_robot(robot_file(v, tmp, key))
    return out


def test_the_oracle_sees_what_matters() -> None:
    """The comparison fails where a body differs: a foot 1 ulp wider, a knee axis turned."""
    robot = load_robot()
    model = build_mjcf(robot).model()
    arr = arrays(model)
    model.geom_size[model.geom("r_foot").id, 0] = np.nextafter(
        model.geom_size[model.geom("r_foot").id, 0], 1.0)
    assert arrays(model)["geom_size"] != arr["geom_size"]
    model.jnt_axis[model.joint("r_knee").id] = (0.0, -1.0, 0.0)
    assert arrays(model)["jnt_axis"] != arr["jnt_axis"]


def test_every_box_robot_compiles_to_the_old_model(tmp_path: Path) -> None:
    robots = _robots(tmp_path)
    assert {"biped18-dynamixel", "biped12-legs", "robotis-mini"} <= set(robots)
    for name, robot in robots.items():
        try:
            assert_same(build_mjcf(robot).model(), old_model(robot))
        except AssertionError as e:
            raise AssertionError(f"{name}: {e}") from e


def test_the_box_tree_is_the_robot_files_body() -> None:
    """Masses, links and frames of the tree itself: the total is the file's [mass] total;
    hinges only for the joints the robot has (no hip yaw on 5-DoF legs), named and
    limited as its joints; the sole frames ``thigh + shin + ankle_height`` below the hips."""
    for robot in (load_robot(), five_dof_robot()):
        tree = robot_tree(robot)
        assert robot.mass is not None
        extras = sum(1 for j in robot.joints if j.name == "head_pan")
        assert tree.mass == pytest.approx(robot.mass.total + 0.02 * extras, rel=1e-12)
        hinges = {link.joint.name: link.joint.range for link in tree.links if link.joint}
        assert hinges == {j.name: (j.min_rad, j.max_rad) for j in robot.joints}
        pos, _ = tree.poses()
        g = robot.geometry
        for side, y in (("r", -1), ("l", 1)):
            foot = tree.index[f"{side}_foot"]
            sole = pos[foot] + next(f.pos for f in tree.links[foot].frames
                                    if f.name == f"{side}_sole")
            assert sole.tolist() == pytest.approx(
                [0.0, y * g.hip_width / 2, -(g.thigh + g.shin + g.ankle_height)], abs=1e-15)


@pytest.mark.parametrize("name", [BOXES[0], *IMPORTED])
def test_biped_mjcf_writes_what_is_simulated(name: str, tmp_path: Path) -> None:
    robot = load_robot(ROBOTS_DIR / f"{name}.toml")
    assert main(["mjcf", "--robot", str(ROBOTS_DIR / f"{name}.toml"),
                 "--out", str(tmp_path)]) == 0
    written = mujoco.MjModel.from_xml_path(str(tmp_path / "scene.xml"))
    assert_same(written, build_mjcf(robot).model())
