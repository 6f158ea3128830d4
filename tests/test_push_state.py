"""The body's state at a push (sim.mujoco.push_state): where each foot's hip holds it, so
that ankle - hip is the foot's step offset the capture limit reads, on every bundled
robot, the imported kits too (whose hip roll and pitch anchors are 2-4 cm apart), against
the leg's own geometry in MuJoCo's kinematics."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from robot.config.bundled import robot_names
from robot.config.robot_file import load_robot
from sim.mujoco.bus import MujocoBus
from sim.mujoco.push_state import body_state


def posed(name: str, angles: dict[str, float]) -> tuple[dict, float]:
    """The state with the torso upright and unturned, every joint at 0 but ``angles``
    [rad]; and the drop [m] from the right hip pitch axis to the right ankle at 0."""
    bus = MujocoBus(load_robot(name))
    bus.open()
    try:
        m = bus.model
        d = mujoco.MjData(m)
        d.qpos[:] = 0.0
        d.qpos[2], d.qpos[3] = 1.0, 1.0                 # high over the floor, unturned
        mujoco.mj_forward(m, d)
        ankle = "r_ankle_pitch" if "r_ankle_pitch" in bus.robot.joint_names else "r_ankle_roll"
        drop = float(d.xanchor[m.joint("r_hip_pitch").id][2]
                     - d.xanchor[m.joint(ankle).id][2])
        for joint, q in angles.items():
            d.qpos[m.jnt_qposadr[m.joint(joint).id]] = q
        mujoco.mj_forward(m, d)
        return body_state(m, d, (False, False)), drop
    finally:
        bus.close()


@pytest.mark.parametrize("name", robot_names())
def test_a_straight_leg_hangs_its_ankle_under_its_hip(name: str) -> None:
    state, _ = posed(name, {})
    for foot in state["feet"]:
        assert foot["ankle"] == pytest.approx(foot["hip"], abs=1e-9)


@pytest.mark.parametrize("name", robot_names())
def test_a_hip_pitch_swings_the_ankle_ahead_of_the_hip_by_the_legs_length(name: str) -> None:
    """0.3 rad of the right hip pitch: the ankle moves L sin 0.3 along x from the hip (L the
    drop from the pitch axis to the ankle), none sideways; the left foot stays."""
    q = 0.3
    state, drop = posed(name, {"r_hip_pitch": q})
    right, left = state["feet"]
    dx, dy = (right["ankle"][i] - right["hip"][i] for i in (0, 1))
    assert abs(dx) == pytest.approx(drop * math.sin(q), rel=1e-3)
    assert abs(dy) < 1e-3
    assert np.allclose(left["ankle"], left["hip"], atol=1e-9)
