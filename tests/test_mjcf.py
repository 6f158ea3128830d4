"""RobotConfig → MJCF: it compiles, matches the config, stands, and agrees with robot.gait.ik FK."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from robot.cli import main  # noqa: E402
from robot.config.bundled import ROBOTS_DIR  # noqa: E402
from robot.config.joint_names import ARM_JOINTS, LEG_JOINTS  # noqa: E402
from robot.config.robot import RobotConfig  # noqa: E402
from robot.config.robot_file import load_robot  # noqa: E402
from robot.gait import ik  # noqa: E402
from robot.servo.firmware import stiffness  # noqa: E402
from sim.mujoco.mjcf import build_mjcf, standing_qpos  # noqa: E402

ROBOTS = sorted(p.name for p in ROBOTS_DIR.glob("*.toml"))
ROBOT = load_robot()
MODEL = build_mjcf(ROBOT).model()


def _robot(name: str) -> RobotConfig:
    return load_robot(ROBOTS_DIR / name)


def _id(model: mujoco.MjModel, kind: mujoco.mjtObj, name: str) -> int:
    i = mujoco.mj_name2id(model, kind, name)
    assert i >= 0, name
    return i


@pytest.mark.parametrize("name", ROBOTS)
def test_model_matches_config(name: str) -> None:
    robot = _robot(name)
    m = build_mjcf(robot).model()
    names = robot.joint_names
    assert [m.actuator(i).name for i in range(m.nu)] == list(names)
    assert m.joint(0).name == "root" and m.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE
    order = [m.joint(i).name for i in range(1, m.njnt)]
    if robot.body is None:   # the box model: the file's order; an imported one: its tree's
        assert order == list(names)
    else:
        assert sorted(order) == sorted(names)
    for i, j in enumerate(robot.joints):
        physics, volts = robot.servo_physics(j), robot.voltage(j)
        jid = _id(m, mujoco.mjtObj.mjOBJ_JOINT, j.name)
        assert m.jnt_range[jid].tolist() == [j.min_rad, j.max_rad]
        assert m.jnt_limited[jid]
        assert m.actuator_ctrlrange[i].tolist() == [j.min_rad, j.max_rad]
        stall = physics.stall_torque(volts)
        assert m.actuator_forcerange[i].tolist() == pytest.approx([-stall, stall], rel=1e-5)
        assert m.actuator_trnid[i, 0] == jid
        assert m.actuator_gainprm[i, 0] == pytest.approx(
            stiffness(robot.servo(j), physics, robot.gains(j), volts), rel=1e-5)
        dof = m.jnt_dofadr[jid]
        assert m.dof_armature[dof] == pytest.approx(physics.armature, rel=1e-5)
        assert m.dof_damping[dof] == pytest.approx(   # torque on: back-EMF + gearbox
            physics.back_emf_damping + physics.viscous, rel=1e-5)
    total = robot.mass.total if robot.mass is not None else robot.body.tree.mass  # type: ignore[union-attr]
    assert m.body_subtreemass[_id(m, mujoco.mjtObj.mjOBJ_BODY, "torso")] == pytest.approx(total)
    assert m.opt.timestep <= 0.002
    assert m.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    for sensor in ("imu_gyro", "imu_accelerometer", "imu_orientation"):
        _id(m, mujoco.mjtObj.mjOBJ_SENSOR, sensor)
    _id(m, mujoco.mjtObj.mjOBJ_CAMERA, "track")


def test_zero_pose_axes_follow_the_right_hand_rule() -> None:
    """At zero pose every body is parallel to the pelvis; knee + swings the shin backward."""
    assert np.allclose(MODEL.body_quat[1:], [1, 0, 0, 0])
    expected = {"hip_yaw": [0, 0, 1], "hip_roll": [1, 0, 0], "hip_pitch": [0, 1, 0],
                "knee": [0, 1, 0], "ankle_pitch": [0, 1, 0], "ankle_roll": [1, 0, 0],
                "shoulder_pitch": [0, 1, 0], "shoulder_roll": [1, 0, 0], "elbow": [0, 1, 0]}
    for name in ROBOT.joint_names:
        assert MODEL.joint(name).axis.tolist() == expected[name[2:]], name
    d = mujoco.MjData(MODEL)
    for joint, q, sign in (("r_knee", 1.0, -1), ("r_hip_pitch", -1.0, 1)):
        d.qpos[:] = MODEL.qpos0
        d.qpos[MODEL.joint(joint).qposadr[0]] = q
        mujoco.mj_kinematics(MODEL, d)
        assert sign * d.site("r_sole").xpos[0] > 0.05, joint


def test_home_keyframe_stands_on_the_soles() -> None:
    d = mujoco.MjData(MODEL)
    mujoco.mj_resetDataKeyframe(MODEL, d, MODEL.key("home").id)
    mujoco.mj_forward(MODEL, d)
    for side in ("r", "l"):
        assert abs(d.site(f"{side}_sole").xpos[2]) < 1e-9
    for name in ROBOT.joint_names:
        assert d.joint(name).qpos[0] == ROBOT.rest.get(name, 0.0)
    assert d.ctrl.tolist() == [ROBOT.rest.get(n, 0.0) for n in ROBOT.joint_names]
    # Only the feet touch, and only the floor (sunk 1 µm: contact needs dist < 0).
    d.qpos[2] -= 1e-6
    mujoco.mj_forward(MODEL, d)
    floor = MODEL.geom("floor").id
    feet = {MODEL.geom("r_foot").id, MODEL.geom("l_foot").id}
    assert d.ncon >= 2
    for c in d.contact[: d.ncon]:
        assert set(c.geom.tolist()) - feet == {floor}


def test_standing_qpos_puts_the_lowest_foot_point_on_the_floor() -> None:
    qpos = standing_qpos(MODEL, {"r_ankle_pitch": 0.3, "l_knee": 0.4})
    d = mujoco.MjData(MODEL)
    d.qpos[:] = qpos
    mujoco.mj_forward(MODEL, d)
    lowest = min(c.dist for c in d.contact[: d.ncon])
    assert lowest == pytest.approx(0.0, abs=1e-9)
    assert d.site("r_sole").xpos[2] > 0.01  # tilted foot: the toe edge touches, not the sole


def test_legs_collide_with_each_other_but_not_within_a_leg() -> None:
    m = MODEL

    def collide(a: str, b: str) -> bool:
        ga, gb = m.geom(a).id, m.geom(b).id
        return bool(m.geom_contype[ga] & m.geom_conaffinity[gb]
                    or m.geom_contype[gb] & m.geom_conaffinity[ga])

    assert collide("r_foot", "floor") and collide("torso", "floor")
    assert collide("r_foot", "l_foot") and collide("r_shin", "l_foot")
    assert collide("r_thigh", "l_thigh") and collide("l_shin", "r_shin")
    assert not collide("r_shin", "r_foot") and not collide("r_thigh", "r_shin")
    assert not collide("torso", "l_thigh")


@settings(max_examples=60, deadline=None)
@given(st.data())
def test_sites_match_the_analytic_fk(data: st.DataObject) -> None:
    """MuJoCo's sole and hand sites, in the pelvis frame, equal robot.gait.ik's FK to 1e-9 m."""
    g = ROBOT.geometry
    d = mujoco.MjData(MODEL)
    pos = data.draw(st.tuples(*[st.floats(-1, 1)] * 3))
    quat = np.array(data.draw(st.tuples(*[st.floats(0.1, 1)] * 4)))
    d.qpos[:3], d.qpos[3:7] = pos, quat / np.linalg.norm(quat)
    q = {}
    for j in ROBOT.joints:
        q[j.name] = data.draw(st.floats(j.min_rad, j.max_rad), label=j.name)
        d.joint(j.name).qpos[0] = q[j.name]
    mujoco.mj_kinematics(MODEL, d)
    torso = d.body("torso")
    rot = torso.xmat.reshape(3, 3)

    def in_pelvis(site: str) -> np.ndarray:
        return rot.T @ (d.site(site).xpos - torso.xpos)

    for side in ("r", "l"):
        leg = np.array([q[f"{side}_{j}"] for j in LEG_JOINTS])
        arm = np.array([q[f"{side}_{j}"] for j in ARM_JOINTS])
        np.testing.assert_allclose(in_pelvis(f"{side}_sole"), ik.leg_fk(g, side, leg),
                                   rtol=0, atol=1e-9)
        np.testing.assert_allclose(in_pelvis(f"{side}_hand"), ik.arm_fk(g, side, arm),
                                   rtol=0, atol=1e-9)


def test_cli_writes_loadable_files(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "mj"
    assert main(["mjcf", "--out", str(out),
                 "--robot", str(ROBOTS_DIR / "biped18-feetech.toml")]) == 0
    assert "scene.xml" in capsys.readouterr().out
    scene = mujoco.MjModel.from_xml_path(str(out / "scene.xml"))
    alone = mujoco.MjModel.from_xml_path(str(out / "robot.xml"))
    assert scene.nu == alone.nu == 18
    assert scene.key("home").name == "home"
    # the STS3215 as Rhoban/bam identified it at 7.4 V (kt 1.2116 N m/A, R 2.6762 ohm,
    # PWM limit 0.97): stall = kt V d / R
    assert scene.actuator_forcerange[0, 1] == pytest.approx(1.21164 * 7.4 * 0.97 / 2.67617,
                                                            rel=1e-4)


def test_cli_reports_an_unwritable_out_dir(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["mjcf", "--out", str(blocker / "sub")]) == 2
    err = capsys.readouterr().err
    assert "--out" in err and err.count("\n") == 1
