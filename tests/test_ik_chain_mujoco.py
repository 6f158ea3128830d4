"""The leg IK against an independent oracle: MuJoCo's forward kinematics of legs written
here by hand as MJCF, each body in a frame of its own (turned by quarter turns, joint
axes given in those frames), not generated from robot.body.legs.LegChain. Each leg's
LegChain is read off its XML by hand (below it). At the IK's angles, MuJoCo puts the sole
where the target asked (random reachable targets from MuJoCo's own FK, and a walk's level
feet) within 1e-6 m and 1e-6 rad; a leg without ankle roll keeps the sole's heading and
pitch and gives up the roll the IK reports, measured on MuJoCo's foot."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from robot.body.legs import LegChain
from robot.gait import xmath as xm
from robot.gait.ik_chain import chain_leg_ik, check_layout

TOL = 1e-6

# Quarter turns as MuJoCo quats (normalised by MuJoCo): about z, y and x, and back.
# 6-DoF, left, yaw axis 16 mm behind and 12 mm inside the roll-pitch point (Newton).
YAW_OFF_HIP = """
<body name="yaw" pos="-0.019 0.035 0" quat="1 0 0 1"><joint name="hip_yaw" axis="0 0 1"/>
 <geom size="0.01"/>
 <body name="roll" pos="0.012 0.016 -0.03" quat="1 0 0 -1"><joint name="hip_roll" axis="1 0 0"/>
  <geom size="0.01"/>
  <body name="thigh" quat="1 1 0 0"><joint name="hip_pitch" axis="0 0 -1"/><geom size="0.01"/>
   <body name="shin" pos="0 -0.11 0" quat="1 -1 0 0"><joint name="knee" axis="0 1 0"/>
    <geom size="0.01"/>
    <body name="ankle" pos="0 0 -0.105" quat="1 0 1 0"><joint name="ankle_pitch" axis="0 1 0"/>
     <geom size="0.01"/>
     <body name="foot" quat="1 0 -1 0"><joint name="ankle_roll" axis="1 0 0"/>
      <geom size="0.01"/><site name="sole" pos="0 0 -0.03"/>
     </body></body></body></body></body></body>"""
YAW_OFF_HIP_LEG = LegChain("l", (-0.035, 0.047, -0.03), 0.11, 0.105, (0.0, 0.0, -0.03),
                           yaw_axis=(-0.019, 0.035))

# 6-DoF, right, roll axis 20 mm above the pitch axis, 15 mm outward along the pitch axes
# (10 at the knee, 5 at the ankle), ankle roll 12 mm below the ankle pitch, sole off it.
ROLL_ABOVE_PITCH = """
<body name="yaw" pos="0.005 -0.04 0"><joint name="hip_yaw" axis="0 0 1"/><geom size="0.01"/>
 <body name="roll" pos="0 0 -0.025" quat="1 0 1 0"><joint name="hip_roll" axis="0 0 1"/>
  <geom size="0.01"/>
  <body name="thigh" pos="0.02 0 0" quat="1 0 -1 0"><joint name="hip_pitch" axis="0 1 0"/>
   <geom size="0.01"/>
   <body name="shin" pos="0 -0.01 -0.1" quat="1 0 0 1"><joint name="knee" axis="1 0 0"/>
    <geom size="0.01"/>
    <body name="ankle" pos="-0.005 0 -0.1" quat="1 0 0 -1"><joint name="ankle_pitch" axis="0 1 0"/>
     <geom size="0.01"/>
     <body name="foot" pos="0 0 -0.012" quat="1 1 0 0"><joint name="ankle_roll" axis="1 0 0"/>
      <geom size="0.01"/><site name="sole" pos="0.01 -0.025 -0.004" quat="1 -1 0 0"/>
     </body></body></body></body></body></body>"""
ROLL_ABOVE_PITCH_LEG = LegChain("r", (0.005, -0.04, -0.025), 0.1, 0.1, (0.01, 0.004, -0.025),
                                yaw_axis=(0.005, -0.04), roll_drop=0.02, lateral=-0.015,
                                ankle_drop=0.012)

# 5-DoF without ankle roll, left, as the Open Duck Mini v2: the yaw axis 16.1 mm ahead of
# the roll-pitch point, the pitch axis 12 mm below the roll axis, 6 mm outward at the knee.
NO_ANKLE_ROLL = """
<body name="yaw" pos="-0.019 0.035 0" quat="1 1 0 0"><joint name="hip_yaw" axis="0 1 0"/>
 <geom size="0.01"/>
 <body name="roll" pos="-0.0161 -0.046 0" quat="1 -1 0 0"><joint name="hip_roll" axis="1 0 0"/>
  <geom size="0.01"/>
  <body name="thigh" pos="0 0 -0.012" quat="1 0 0 1"><joint name="hip_pitch" axis="1 0 0"/>
   <geom size="0.01"/>
   <body name="shin" pos="0.006 0 -0.0786" quat="1 0 0 -1"><joint name="knee" axis="0 1 0"/>
    <geom size="0.01"/>
    <body name="foot" pos="0 0 -0.0787" quat="1 0 1 0"><joint name="ankle_pitch" axis="0 1 0"/>
     <geom size="0.01"/><site name="sole" pos="0.035 0.01 0.02" quat="1 0 -1 0"/>
    </body></body></body></body></body>"""
NO_ANKLE_ROLL_LEG = LegChain("l", (-0.0351, 0.035, -0.046), 0.0786, 0.0787,
                             (0.02, 0.01, -0.035), yaw_axis=(-0.019, 0.035), roll_drop=0.012,
                             lateral=0.006, has_ankle_roll=False)

# 5-DoF without ankle roll, right, the roll before the yaw; the yaw axis 10 mm off the
# roll axis both ways (Newton), the pitch axis 25 mm below the roll axis.
ROLL_YAW = """
<body name="roll" pos="0 -0.045 -0.02"><joint name="hip_roll" axis="1 0 0"/><geom size="0.01"/>
 <body name="yaw" pos="0.01 -0.01 -0.01" quat="1 0 1 0"><joint name="hip_yaw" axis="-1 0 0"/>
  <geom size="0.01"/>
  <body name="thigh" pos="0.015 0.01 -0.01" quat="1 0 -1 0"><joint name="hip_pitch" axis="0 1 0"/>
   <geom size="0.01"/>
   <body name="shin" pos="0 -0.004 -0.09"><joint name="knee" axis="0 1 0"/><geom size="0.01"/>
    <body name="foot" pos="0 0 -0.095" quat="1 0 0 1"><joint name="ankle_pitch" axis="1 0 0"/>
     <geom size="0.01"/><site name="sole" pos="-0.005 -0.015 -0.03" quat="1 0 0 -1"/>
    </body></body></body></body></body>"""
ROLL_YAW_LEG = LegChain("r", (0.0, -0.045, -0.02), 0.09, 0.095, (0.015, -0.005, -0.03),
                        yaw_axis=(0.01, -0.055), roll_drop=0.025, lateral=-0.004,
                        has_ankle_roll=False, order="roll_yaw")

LEGS = {"yaw_off_hip": (YAW_OFF_HIP, YAW_OFF_HIP_LEG),
        "roll_above_pitch": (ROLL_ABOVE_PITCH, ROLL_ABOVE_PITCH_LEG),
        "no_ankle_roll": (NO_ANKLE_ROLL, NO_ANKLE_ROLL_LEG), "roll_yaw": (ROLL_YAW, ROLL_YAW_LEG)}
ORDER = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")


class Model:
    """One hand-written leg in MuJoCo: its FK at the IK's six angles."""

    def __init__(self, xml: str) -> None:
        self.m = mujoco.MjModel.from_xml_string(f"<mujoco><worldbody>{xml}</worldbody></mujoco>")
        self.d = mujoco.MjData(self.m)
        names = [self.m.joint(i).name for i in range(self.m.njnt)]
        self.slots = [(names.index(n), i) for i, n in enumerate(ORDER) if n in names]

    def fk(self, q: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
        for adr, i in self.slots:
            self.d.qpos[self.m.jnt_qposadr[adr]] = q[i]
        mujoco.mj_kinematics(self.m, self.d)
        return self.d.site("sole").xpos.copy(), self.d.site("sole").xmat.reshape(3, 3).copy()


def rot_angle(a: np.ndarray, b: np.ndarray) -> float:
    """The angle [rad] of the rotation between two rotation matrices."""
    c = (np.trace(a.T @ b) - 1.0) / 2.0
    s = np.linalg.norm([*(a.T @ b - b.T @ a)[[2, 0, 1], [1, 2, 0]]]) / 2.0
    return math.atan2(s, c)


def random_angles(rng: np.random.Generator, leg: LegChain) -> tuple[float, ...]:
    """A pose of the walking range and beyond: the knee 0.1-1.8 rad, the hip within 0.9
    rad of the ankle's up axis (not near the ankle roll's singularity, the hip in the
    sole's plane, where the roll's two roots meet and no closed form is well-conditioned)."""
    knee = rng.uniform(0.1, 1.8)
    lean = math.atan2(leg.thigh * math.sin(knee), leg.shin + leg.thigh * math.cos(knee))
    yaw = rng.uniform(-0.4, 0.4) if leg.has_yaw else 0.0
    ankle_roll = rng.uniform(-0.3, 0.3) if leg.has_ankle_roll else 0.0
    return (yaw, rng.uniform(-0.3, 0.3), rng.uniform(-0.8, 0.6), knee,
            rng.uniform(-0.9, 0.9) - lean, ankle_roll)


@pytest.mark.parametrize("name", LEGS)
def test_the_hand_written_chain_is_the_xml_at_the_zero_pose(name: str) -> None:
    """The transcription checked where it can be by eye: sole and foot frame at zero."""
    xml, leg = LEGS[name]
    check_layout(leg)
    sole, rot = Model(xml).fk((0.0,) * 6)
    assert np.abs(sole - leg.zero_sole()).max() < 1e-12
    assert np.abs(rot - np.eye(3)).max() < 1e-12


@pytest.mark.parametrize("name", LEGS)
def test_mujoco_puts_the_sole_where_the_ik_aimed_on_random_reachable_targets(name: str) -> None:
    xml, leg = LEGS[name]
    model = Model(xml)
    rng = np.random.default_rng(31)
    worst = 0.0, 0.0
    for _ in range(300):
        sole, rot = model.fk(random_angles(rng, leg))
        sol = chain_leg_ik(leg, tuple(sole), tuple(rot.ravel()))  # type: ignore[arg-type]
        assert sol.reachable
        got, got_rot = model.fk(sol.q)
        worst = (max(worst[0], float(np.abs(got - sole).max())),
                 max(worst[1], rot_angle(got_rot, rot)))
    assert worst[0] < TOL and worst[1] < TOL, worst


@pytest.mark.parametrize("name", LEGS)
def test_mujoco_puts_a_walks_level_feet_where_the_ik_aimed(name: str) -> None:
    """The gait's targets: the sole about its zero place, 1-4 cm up, stepped, turned and
    tipped at the toe; a leg without ankle roll keeps the sole point and the foot's x axis
    (heading, pitch) exactly and loses the roll the IK says, as MuJoCo's foot shows it."""
    xml, leg = LEGS[name]
    model = Model(xml)
    zero = np.array(leg.zero_sole())
    for i, (dx, dy, up, yaw, pitch) in enumerate(np.random.default_rng(7).uniform(
            [-0.04, -0.015, 0.01, -0.3, -0.2], [0.04, 0.015, 0.04, 0.3, 0.2], (200, 5))):
        sole = tuple(float(v) for v in zero + (dx, dy, up))
        rot = xm.rz_ry(float(yaw) if leg.has_yaw else 0.0, float(pitch))
        sol = chain_leg_ik(leg, sole, rot)  # type: ignore[arg-type]
        assert sol.reachable, i
        got, got_rot = model.fk(sol.q)
        want = np.array(rot).reshape(3, 3)
        assert np.abs(got - sole).max() < TOL
        assert np.abs(got_rot[:, 0] - want[:, 0]).max() < TOL           # heading, pitch
        normals = math.atan2(float(np.linalg.norm(np.cross(got_rot[:, 2], want[:, 2]))),
                             float(got_rot[:, 2] @ want[:, 2]))
        assert abs(normals - abs(sol.roll_lost)) < TOL
        rel = got_rot.T @ want                      # = rot_x(roll given up)
        assert abs(math.atan2(rel[2, 1], rel[1, 1]) - sol.roll_lost) < TOL
        if leg.has_ankle_roll:
            assert sol.roll_lost == 0.0 and rot_angle(got_rot, want) < TOL
