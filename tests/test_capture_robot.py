"""A robot's numbers for its capture limit (robot.balance.capture_robot) and the servo's
swing of a load (robot.servo.move_time), against hand computations and MuJoCo's own
model: the DC motor's speed-up at full duty, a slewed goal, the legs' straddle at the
walk's height, a joint limit that cuts the reach (checked by forward kinematics), the
swinging leg's inertia against MuJoCo's joint-space mass matrix (box models and the
imported kits), every bundled robot's 0-step limit standing still."""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from robot.balance.capture_limit import Foot, PushState, limits, numbers
from robot.balance.capture_robot import (
    FOOT_GAP_M,
    Leg,
    joint_law,
    leg_length,
    leg_load,
    reach,
    swing,
)
from robot.config.bundled import robot_names
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.ik import leg_fk_full
from robot.servo.law import Law
from robot.servo.move_time import Load, time_to, trajectory
from sim.mujoco.bus import MujocoBus

#: An ideal servo: 1 N m at stall, kt^2 / R = 0.1 N m s/rad (10 rad/s no load), no
#: friction, a stiff law (full duty from 1 mrad of error), no armature.
IDEAL = Law(kp=1000.0, kd=0.0, ki=0.0, margin=0.0, max_velocity=math.inf, drive=1.0,
            max_duty=1.0, back_emf=0.1, viscous=0.0, coulomb=0.0, stribeck=0.0,
            stribeck_speed=0.1, load_friction=0.0, armature=0.0, kt=1.0)


def test_a_swing_at_full_duty_is_the_dc_motors_speed_up() -> None:
    """Far from the goal: I q'' = 1 - 0.1 q', so q' = 10 (1 - e^(-t / tau)), tau = I /
    0.1, and q = 10 (t - tau (1 - e^(-t / tau)))."""
    inertia = 0.005
    tau = inertia / 0.1
    times = np.array([0.0, 0.02, 0.05, 0.1, 0.2])
    q = trajectory(IDEAL, Load(inertia), start=0.0, target=100.0, slew=math.inf, times=times)
    want = 10.0 * (times - tau * (1.0 - np.exp(-times / tau)))
    assert q == pytest.approx(want, abs=2e-3)


def test_a_slewed_goal_is_followed_at_the_slew() -> None:
    """Goal slewed at 2 rad/s toward 1 rad: the servo (far faster) follows it a few mrad
    behind and passes 0.5 rad at 0.25 s."""
    t = time_to(IDEAL, Load(0.001), start=0.0, target=1.0, slew=2.0, reach=0.5)
    assert t == pytest.approx(0.25, abs=0.01)
    # The firmware's own slew (max_velocity) applies as well: the slower of the two.
    slow = dataclasses.replace(IDEAL, max_velocity=1.0)
    assert time_to(slow, Load(0.001), start=0.0, target=1.0, slew=2.0,
                   reach=0.5) == pytest.approx(0.5, abs=0.01)


def test_gravity_slows_a_swing_that_lifts_the_leg() -> None:
    load = Load(0.005, mass=0.4, arm=0.14)
    up = time_to(IDEAL, load, start=0.0, target=0.6, slew=math.inf, reach=0.5)
    flat = time_to(IDEAL, Load(0.005), start=0.0, target=0.6, slew=math.inf, reach=0.5)
    assert up > flat
    assert trajectory(IDEAL, load, start=0.0, target=0.0, slew=math.inf,
                      times=[0.0, 0.1])[1] == pytest.approx(0.0, abs=1e-3)


ROBOT = load_robot("biped18-dynamixel")
STANCE = 0.88


def test_the_legs_straddle_at_the_walks_height() -> None:
    """Straight legs at h = 0.88 x 0.22 m reach sqrt(0.22^2 - h^2) = 0.1045 m each way;
    the Dynamixel robot's joint limits do not cut that: a step of 0.209 m. Sideways
    the hip roll's 0.5 rad: 0.09 + 2 x 0.1045 m. Inward the soles' gap."""
    g = ROBOT.geometry
    h = STANCE * g.leg_length
    half = math.sqrt(g.leg_length ** 2 - h ** 2)
    r = reach(ROBOT, STANCE)
    assert r.forward == pytest.approx(2 * half, abs=5e-4)
    assert r.back == pytest.approx(2 * half, abs=5e-4)
    assert r.out == pytest.approx(g.hip_width + 2 * half, abs=5e-4)
    assert r.inward == pytest.approx(g.foot_width + FOOT_GAP_M)


def test_a_joint_limit_cuts_the_reach_where_forward_kinematics_puts_the_foot() -> None:
    """Hip pitch limited to 0.2 rad (the rear leg of a straddle pitches its hip > 0): the
    step shrinks, and at the reach found the rear leg's hip is at that limit with its
    sole where the step puts it (leg_fk_full, not the IK)."""
    joints = tuple(dataclasses.replace(j, max_rad=0.2) if j.name.endswith("hip_pitch")
                   else j for j in ROBOT.joints)
    robot = dataclasses.replace(ROBOT, joints=joints)
    r = reach(robot, STANCE)
    assert r.forward < reach(ROBOT, STANCE).forward - 0.02
    leg = Leg(robot, STANCE * robot.geometry.leg_length)
    q = leg.solve("l", -0.5 * r.forward, 0.0)
    assert q is not None and q[2] == pytest.approx(0.2, abs=2e-3)
    (x, _, z), _ = leg_fk_full(robot.geometry, "l", q)
    assert x == pytest.approx(-0.5 * r.forward, abs=1e-6)
    assert z == pytest.approx(-leg.h - robot.geometry.ankle_height, abs=1e-6)


@pytest.mark.parametrize("name", ["biped18-dynamixel", "robotis-mini", "robotis-op3",
                                  "open-duck-mini-v2"])
def test_the_swinging_legs_inertia_is_mujocos(name: str) -> None:
    """The body tree's links summed about the hip axis (parallel axes, each link's own
    inertia turned into the world) against MuJoCo's mass matrix at the same pose (its
    diagonal at the hip pitch and roll dofs, less the armature), for box models and
    imported ones; the armature is the servo law's."""
    robot = load_robot(name)
    h = STANCE * leg_length(robot)
    q = Leg(robot, h).solve("r", 0.0, 0.0)
    assert q is not None
    bus = MujocoBus(robot)
    bus.open()
    try:
        m = bus.model
        d = mujoco.MjData(m)
        for joint, v in zip(("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch",
                             "ankle_roll"), q, strict=True):
            if f"r_{joint}" in robot.joint_names:
                d.qpos[m.jnt_qposadr[m.joint(f"r_{joint}").id]] = v
        mujoco.mj_forward(m, d)
        full = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, full)
        for axis in ("pitch", "roll"):
            dof = m.jnt_dofadr[m.joint(f"r_hip_{axis}").id]
            law = joint_law(robot, f"r_hip_{axis}")
            assert m.dof_armature[dof] == pytest.approx(law.armature)
            link = full[dof, dof] - m.dof_armature[dof]
            assert leg_load(robot, h, axis).inertia == pytest.approx(link, rel=1e-3), axis
    finally:
        bus.close()


def test_the_swing_gets_further_with_time_and_stops_at_its_target() -> None:
    s = swing(ROBOT, STANCE, "pitch", -0.05, 0.1)
    assert s.offset[0] == pytest.approx(-0.05, abs=2e-3)   # held against gravity
    assert np.all(np.diff(s.offset) >= 0.0) and s.offset.max() <= 0.1
    # At the file's 5 rad/s the leg line turns 0.73 rad (atan of 0.15 m over 0.194 m
    # between the two offsets) in no less than 0.146 s.
    arrive = s.times[np.argmax(s.offset >= 0.0999)]
    h = STANCE * ROBOT.geometry.leg_length
    turn = math.atan2(0.1, h) - math.atan2(-0.05, h)
    assert arrive >= turn / ROBOT.joint("r_hip_pitch").max_speed_rad_s
    assert arrive < 2.0 * turn / ROBOT.joint("r_hip_pitch").max_speed_rad_s


@pytest.mark.parametrize("name", robot_names())
def test_every_bundled_robots_limit_standing_still_is_its_toe(name: str) -> None:
    """Every bundled robot, the imported kits too: standing on the left foot at rest, the
    0-step limit of a forward push is min(toe, ankle stall torque / weight) x M w0, with
    the weight MuJoCo's model's and the stall the servo model's at the robot's voltage;
    with a step it is larger."""
    robot = load_robot(name)
    params = load_gait("walk").for_robot(robot)
    n = numbers(robot, params.stance, params.foot_spread)
    bus = MujocoBus(robot)
    bus.open()
    try:
        mass = float(np.sum(bus.model.body_mass))
    finally:
        bus.close()
    g = robot.geometry
    stall = min(robot.servo_physics(robot.joint(f"{s}_ankle_pitch")).stall_torque(
        robot.voltage(robot.joint(f"{s}_ankle_pitch"))) for s in "rl")
    toe = min(g.foot_forward + 0.5 * g.foot_length, stall / (mass * 9.81))
    corners = np.array([[g.foot_forward + sx * g.foot_length / 2, sy * g.foot_width / 2]
                        for sx in (-1, 1) for sy in (-1, 1)])
    left = Foot(True, (0.0, 0.0), (0.0, 0.0), corners)
    right = Foot(False, (0.0, -g.hip_width), (0.0, -g.hip_width), corners - [0, g.hip_width])
    z = params.stance * leg_length(robot)
    lim = limits(PushState(z, (0.0, 0.0), mass, (right, left)), n, 0.0)
    assert lim[0] == pytest.approx(toe * mass * math.sqrt(9.81 / z), rel=1e-3)
    assert lim[1] > lim[0] > 0.0
