"""robot.balance.kinematic.sole_point, the balance estimate's leg forward kinematics on
floats, is robot.gait.ik.leg_fk_full's sole point bit for bit: on every bundled robot's
geometry, both legs, random angles over and past the joint ranges, and the poses where
terms vanish (zero angles, signed zeros, right angles)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.balance.kinematic import sole_point
from robot.config.bundled import robot_names
from robot.config.robot_file import load_robot
from robot.gait.ik import leg_fk_full

SPECIAL = (0.0, -0.0, math.pi / 2, -math.pi / 2, math.pi, 1e-300)


@pytest.mark.parametrize("robot", robot_names())
def test_the_sole_point_is_the_leg_fk_s_bit_for_bit(robot: str) -> None:
    g = load_robot(robot).geometry
    rng = np.random.default_rng(7)
    poses = [tuple(float(v) for v in rng.uniform(-3.5, 3.5, 6)) for _ in range(400)]
    poses += [tuple(float(v) for v in rng.choice(SPECIAL, 6)) for _ in range(200)]
    for side in ("r", "l"):
        for q in poses:
            want, _ = leg_fk_full(g, side, q)
            got = sole_point(g, side, q)
            assert [v.hex() for v in got] == [float(v).hex() for v in want], (side, q)
