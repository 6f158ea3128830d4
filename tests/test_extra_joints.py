"""Extra joints (a head pan and tilt, a jaw, a tail) everywhere: the turn axis and place
their names give, in the simulation (MuJoCo's own kinematics as the oracle), in the BVH
export (read back with bvhio) and through the import, and their own panel in the plots."""

from __future__ import annotations

import math
from pathlib import Path

import bvhio
import mujoco
import numpy as np
import pytest
from extra_robot import EXTRAS, write_extra_robot

import robot.cli as cli
from robot.config.extra_joints import extra_layout
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.motion.takes import read_take
from robot.previs.curves import curves_figure
from robot.previs.plots import read_table, record_figure
from sim.mujoco.mjcf import build_mjcf


@pytest.fixture
def extras(tmp_path: Path) -> Path:
    return write_extra_robot(tmp_path)


def test_names_give_axis_and_place(extras: Path) -> None:
    layout = {e.name: e for e in extra_layout(load_robot(str(extras)))}
    assert {n: e.axis for n, e in layout.items()} == {"head_pan": "z", "head_tilt": "y",
                                                      "jaw": "y", "tail": "z"}
    assert layout["head_tilt"].parent == "head_pan" and layout["head_pan"].parent is None
    assert layout["jaw"].parent == "head_tilt" and layout["tail"].parent is None
    assert layout["head_tilt"].kind == "head" and layout["tail"].offset[0] < 0


def test_in_the_sim_the_tilt_nods_and_the_pan_turns(extras: Path) -> None:
    model = mujoco.MjModel.from_xml_string(build_mjcf(load_robot(str(extras))).robot)
    data = mujoco.MjData(model)
    head = model.body("head_tilt_link").id
    jaw = model.body("jaw_link").id

    def jaw_in_head(joint: str, angle: float) -> np.ndarray:
        data.qpos[:] = model.qpos0
        data.qpos[model.jnt_qposadr[model.joint(joint).id]] = angle
        mujoco.mj_kinematics(model, data)
        return data.xmat[head].reshape(3, 3).T @ (data.xpos[jaw] - data.xpos[head])

    def world(joint: str, angle: float) -> np.ndarray:
        data.qpos[:] = model.qpos0
        data.qpos[model.jnt_qposadr[model.joint(joint).id]] = angle
        mujoco.mj_kinematics(model, data)
        return data.xpos[jaw] - data.xpos[model.body("head_pan_link").id]
    rest = world("head_tilt", 0.0)
    nod = world("head_tilt", 0.5)     # about y: x and z change, y does not
    assert abs(nod[1] - rest[1]) < 1e-9 and np.linalg.norm(nod - rest) > 1e-3
    pan = world("head_pan", 0.5)      # about z: the height does not change
    assert abs(pan[2] - rest[2]) < 1e-9 and np.linalg.norm(pan - rest) > 1e-3
    # The head carries the jaw: in the head's frame the jaw does not move when it nods.
    assert np.allclose(jaw_in_head("head_tilt", 0.5), jaw_in_head("head_tilt", 0.0))
    visible = [g for g in range(model.ngeom) if model.geom_bodyid[g] == head
               and model.geom_group[g] == 2]
    assert len(visible) >= 2          # the servo and the head shell


def test_bvh_export_has_the_extra_bones_and_import_gives_them_back(
        extras: Path, tmp_path: Path) -> None:
    anim, take = tmp_path / "walk.bvh", tmp_path / "walk.take.jsonl"
    assert cli.main(["export", "--robot", str(extras), "--gait", "walk", "--seconds", "1",
                     "--out", str(anim)]) == 0
    joints = {j.Name: j for j, _, _ in bvhio.readAsBvh(str(anim)).Root.layout()}
    # BVH axes: robot y (tilt) is X, robot z (pan) is Y.
    for name, axis in (("head_tilt", (1, 0, 0)), ("head_pan", (0, 1, 0)), ("jaw", (1, 0, 0)),
                       ("tail", (0, 1, 0))):
        r = joints[name].Keyframes[5].Rotation
        h = EXTRAS[name][1] / 2
        want = np.array([math.cos(h), *(math.sin(h) * np.array(axis))])
        got = np.array([r.w, r.x, r.y, r.z])
        assert min(np.abs(got - want).max(), np.abs(got + want).max()) < 1e-6, name
    assert cli.main(["import", str(anim), "--robot", str(extras), "--out", str(take)]) == 0
    back = read_take(take)
    for name, (_, angle) in EXTRAS.items():
        assert np.abs(back.q[:, back.header.joints.index(name)] - angle).max() < 1e-6


def test_plots_give_extra_joints_their_own_panel(extras: Path, tmp_path: Path) -> None:
    robot = load_robot(str(extras))
    t = np.arange(0, 1, 0.01)
    channels, q = GaitEngine(robot, load_gait("walk").params).curves(t)
    fig = curves_figure(t, channels, robot.joint_names, q, title="x")
    panels = {ax.get_title(loc="left"): ax for ax in fig.axes}
    assert {ln.get_label() for ln in panels["extra joints"].get_lines()} == set(EXTRAS)
    assert not set(EXTRAS) & {ln.get_label() for ln in panels["leg joints"].get_lines()}
    record = tmp_path / "run.csv"
    assert cli.main(["walk", "--robot", str(extras), "--seconds", "1",
                     "--record", str(record)]) == 0
    fig = record_figure(read_table(record))
    titles = [ax.get_title(loc="left") for ax in fig.axes]
    assert any(t.startswith("extra joints") for t in titles)
    assert "loads: extra" in titles and "loads: right leg" in titles
