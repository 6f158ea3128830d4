"""The capture limit (robot.balance.capturability, robot.balance.capture_limit) on cases
worked by hand: the sole alone (0 steps), Koolen et al.'s N-step radius, a step time long
against 1 / omega0, the limit growing with the step length and shrinking with the step
time, a lateral push toward the standing foot, and the whole limit of a robot against a
step-by-step integration of the pendulum (a second, differently written computation)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.balance.capturability import (
    Box,
    Interval,
    Step,
    capture_point_after,
    disc_radius,
    omega0,
    polygon_exit,
    ray_exit,
    region,
)
from robot.balance.capture_limit import Foot, Numbers, PushState, limits, numbers
from robot.balance.capture_robot import swing
from robot.config.robot_file import load_robot

#: A pendulum with omega0 = 6 /s exactly and a 2 kg robot: 1 N*s moves the capture
#: point 1 / (2 x 6) m.
W0 = 6.0
HEIGHT = 9.81 / 36.0
MASS = 2.0
SOLE = Box(Interval(-0.05, 0.08), Interval(-0.0375, 0.0375))
CORNERS = np.array([[-0.05, -0.0375], [0.08, -0.0375], [0.08, 0.0375], [-0.05, 0.0375]])


def test_omega0_and_the_capture_point_under_a_held_centre_of_pressure() -> None:
    assert omega0(HEIGHT) == pytest.approx(W0)
    # r(t) = p + (r0 - p) e^(w t): 2 cm beyond p grows to 2 e cm after 1 / w0.
    assert capture_point_after(0.05, 0.03, W0, 1.0 / W0) == pytest.approx(0.03 + 0.02 * math.e)
    with pytest.raises(ValueError):
        omega0(0.0)


def test_zero_steps_is_the_sole_alone() -> None:
    """Standing at rest over the ankle: forward up to the toe, 0.08 m x 12 N*s/m; back to
    the heel 0.05 x 12; sideways the edge 0.0375 x 12; at 45 deg the edge comes first,
    0.0375 sqrt(2) x 12."""
    k = 1.0 / (MASS * W0)
    for deg, want in ((0, 0.96), (180, 0.6), (90, 0.45), (270, 0.45),
                      (45, 0.0375 * math.sqrt(2) * 12), (135, 0.0375 * math.sqrt(2) * 12)):
        u = (k * math.cos(math.radians(deg)), k * math.sin(math.radians(deg)))
        assert polygon_exit((0.0, 0.0), u, CORNERS) == pytest.approx(want, abs=1e-9), deg
        assert ray_exit((0.0, 0.0), u, SOLE) == pytest.approx(want, abs=1e-9), deg
    # Outside the sole already: no push is survivable without a step.
    assert polygon_exit((0.1, 0.0), (k, 0.0), CORNERS) == 0.0
    assert ray_exit((0.1, 0.0), (-k, 0.0), SOLE) == 0.0


def symmetric(n: int, r: float, reach: float, dt: float) -> float:
    """The forward edge of the N-step region for a square foot of half size r and a
    reach in every direction."""
    foot = Box(Interval(-r, r), Interval(-r, r))
    step = Step(foot, Box(Interval(-reach, reach), Interval(-reach, reach)), dt)
    return float(region([step] * n, foot, W0).x.hi)


def test_the_interval_recursion_is_the_papers_radius() -> None:
    """Koolen et al.: d_N = (d_(N-1) - r + l) e^(-w dt) + r, d_0 = r. By hand for r 0.08,
    l 0.15, w 6, dt 0.2: d_1 = 0.08 + 0.15 e^-1.2 = 0.125179, d_2 = 0.08 + (0.125179 -
    0.08 + 0.15) e^-1.2 = 0.138787."""
    e = math.exp(-1.2)
    assert disc_radius(0, 0.08, 0.15, W0, 0.2) == 0.08
    assert disc_radius(1, 0.08, 0.15, W0, 0.2) == pytest.approx(0.08 + 0.15 * e)
    assert disc_radius(2, 0.08, 0.15, W0, 0.2) == pytest.approx(0.08 + (0.15 * e + 0.15) * e)
    assert 0.08 + 0.15 * e == pytest.approx(0.125179, abs=1e-6)
    for n in (0, 1, 2, 3):
        assert symmetric(n, 0.08, 0.15, 0.2) == pytest.approx(
            disc_radius(n, 0.08, 0.15, W0, 0.2), abs=1e-12)
    # The push: d_1 x M x w0 = 0.125179 x 12 = 1.50215 N*s.
    one = region([Step(SOLE, Box(Interval(-0.15, 0.15), Interval(-0.15, 0.15)), 0.2)],
                 Box(Interval(-0.08, 0.08), Interval(-0.08, 0.08)), W0)
    assert ray_exit((0.0, 0.0), (1.0 / 12.0, 0.0), one) == pytest.approx(1.50215, abs=1e-5)


def test_a_step_long_against_one_over_omega0_adds_nothing() -> None:
    """dt = 10 / w0: the step's share l e^-10 = 4.5e-5 l; the region is the sole's."""
    long = symmetric(1, 0.08, 0.15, 10.0 / W0)
    assert long == pytest.approx(0.08 + 0.15 * math.exp(-10.0), abs=1e-15)
    assert long - 0.08 < 1e-5


def test_the_limit_grows_with_the_step_length_and_shrinks_with_the_step_time() -> None:
    lengths = [symmetric(1, 0.08, x, 0.2) for x in (0.0, 0.05, 0.1, 0.15, 0.2)]
    assert lengths == sorted(lengths) and len(set(lengths)) == 5
    assert lengths[0] == pytest.approx(0.08)            # no step: the sole
    times = [symmetric(2, 0.08, 0.15, t) for t in (0.1, 0.2, 0.3, 0.5, 1.0)]
    assert times == sorted(times, reverse=True) and len(set(times)) == 5


def test_a_lateral_push_toward_the_standing_foot_gets_no_help_from_the_other_foot() -> None:
    """Standing on the left foot, the right one swings: it lands at least 0.08 m to the
    right of the left ankle (the soles may not cross). A push to the left: the region's
    left edge is 0.0375 (1 - e^-wt) + e^-wt (-0.08 + 0.0375), below the sole's own 0.0375
    for any t: the step only hurts, so the 1-step limit is the sole's at the longest
    step time."""
    reach = Box(Interval(-0.2, 0.2), Interval(-0.3, -0.08))
    for t in (0.1, 0.3, 1.0):
        e = math.exp(-W0 * t)
        r = region([Step(SOLE, reach, t)], SOLE, W0)
        assert r.y.hi == pytest.approx(0.0375 * (1 - e) + e * (-0.08 + 0.0375))
        assert r.y.hi < 0.0375
    # Two steps: the left foot then steps out 0.3 m: this time it helps.
    two = region([Step(SOLE, reach, 0.2), Step(SOLE, Box(reach.x, Interval(0.08, 0.3)), 0.2)],
                 SOLE, W0)
    assert two.y.hi > 0.0375


def test_the_regions_broadcast_over_grids_of_step_times() -> None:
    ts = np.array([0.1, 0.2, 0.4])
    grid = region([Step(SOLE, Box(Interval(-0.15, 0.15), Interval(-0.15, 0.15)), ts)],
                  SOLE, W0)
    for i, t in enumerate(ts):
        one = region([Step(SOLE, Box(Interval(-0.15, 0.15), Interval(-0.15, 0.15)),
                           float(t))], SOLE, W0)
        assert float(grid.x.hi[i]) == pytest.approx(float(one.x.hi))
        assert float(grid.y.lo[i]) == pytest.approx(float(one.y.lo))


# ------------------------------------------------------------------ a robot's limit

ROBOT = load_robot("biped18-dynamixel")
STANCE = 0.88


def standing_on_left(vx: float) -> PushState:
    """The left foot down, its ankle under the centre of mass, the right foot beside it
    in the air (its ankle 9 cm to the right, under its hip), moving forward at ``vx``."""
    g = ROBOT.geometry
    left = Foot(True, (0.0, 0.0), (0.0, -0.0),
                np.array([[g.foot_forward + sx * g.foot_length / 2, sy * g.foot_width / 2]
                          for sx in (-1, 1) for sy in (-1, 1)]))
    right = Foot(False, (0.0, -g.hip_width), (0.0, -g.hip_width), left.sole - [0, g.hip_width])
    left = left._replace(hip=(0.0, 0.0))
    return PushState(HEIGHT, (vx, 0.0), MASS, (right, left))


def test_a_robots_zero_step_limit_is_its_sole_within_its_ankle_servos_torque() -> None:
    """The XL430's stall at 11.1 V (its physics, robot.servo.physics) over the robot's
    weight is under its toe (8 cm): the forward limit is that, x M w0; backward the heel
    (5 cm); sideways the edge (3.75 cm)."""
    n = numbers(ROBOT, STANCE)
    ankle = ROBOT.joint("l_ankle_pitch")
    stall = ROBOT.servo_physics(ankle).stall_torque(ROBOT.voltage(ankle))
    toe = min(0.08, stall / (ROBOT.mass.total * 9.81))
    assert toe < 0.08
    s = standing_on_left(0.0)
    assert limits(s, n, 0.0)[0] == pytest.approx(toe * MASS * W0, rel=1e-9)
    assert limits(s, n, 180.0)[0] == pytest.approx(0.05 * MASS * W0, rel=1e-9)
    assert limits(s, n, 90.0)[0] == pytest.approx(0.0375 * MASS * W0, rel=1e-9)


def lipm_one_step(s: PushState, n: Numbers, j: float) -> bool:
    """Forward push ``j``: integrate the pendulum (1 ms Euler) with the centre of pressure
    at the toe until the swinging foot lands where it has got by then (the robot's swing
    table, ankle to ankle), then on the new foot; captured if the capture point ends
    inside its sole region. Tried at every landing time of the table."""
    dt, w2 = 1e-4, W0 * W0
    toe = float(n.sole.x.hi)
    first = 2.0 * swing(ROBOT, STANCE, "pitch", 0.0, 0.5 * n.reach.forward).offset
    for k in range(0, len(n.times), 4):
        t_land = float(n.times[k])
        c, v, t = 0.0, s.velocity[0] + j / s.mass, 0.0
        while t < t_land - 1e-12:
            v += w2 * (c - toe) * dt
            c += v * dt
            t += dt
        ankle = float(first[k])
        xi = c + v / W0
        if ankle + float(n.sole.x.lo) <= xi <= ankle + float(n.sole.x.hi):
            return True
    return False


def test_a_robots_one_step_limit_matches_the_pendulum_integrated_step_by_step() -> None:
    n = numbers(ROBOT, STANCE)
    s = standing_on_left(0.0)
    lim = limits(s, n, 0.0)
    assert lim[0] < lim[1] <= lim[2]
    assert lipm_one_step(s, n, 0.97 * lim[1])
    assert not lipm_one_step(s, n, 1.03 * lim[1])
