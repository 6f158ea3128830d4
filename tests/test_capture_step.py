"""The capture step's pure functions (robot.balance.capture_step): when each foot of the
paper's gait lands, checked against the gait's own foot lift (robot.gait), and where and
when a step lands, checked against the linear inverted pendulum integrated step by step."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.balance.capture_step import Reach, plan_step, swing_phase_left, tempo_for
from robot.config.params import GaitParams
from robot.config.robot_file import load_robot
from robot.gait import expressions as gait
from robot.gait.targets import body_targets

W0 = math.sqrt(9.81 / 0.23)            # [1/s]
WIDE = Reach(0.08, 0.08, 0.08, 0.08)


def _lifts(p: GaitParams, thetas: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    g = load_robot("biped18-dynamixel").geometry
    right, left = [], []
    for th in thetas:
        t = body_targets(gait.channels(gait.Phase(th, th, th, th, th), p), p, g)
        right.append(float(t.lift_r))
        left.append(float(t.lift_l))
    return np.array(right), np.array(left)


@pytest.mark.parametrize("delta_f", [0.0, -0.25, 0.3])
def test_touchdown_is_where_the_gaits_foot_lift_ends(delta_f: float) -> None:
    """Walking the phase forward from each theta by swing_phase_left, the gait's lift of
    that foot (robot.gait.targets) has just reached 0 after being positive."""
    p = GaitParams().replace({"delta_f": delta_f})
    for foot in (0, 1):
        for theta in np.linspace(0.0, 2 * math.pi, 13)[:-1]:
            left = swing_phase_left(float(theta), delta_f, foot)
            assert 0.0 <= left < 2 * math.pi
            r, l_ = _lifts(p, np.array([theta + left - 1e-3, theta + left + 1e-3]))
            mine = r if foot == 0 else l_
            assert mine[0] > 0.0 and mine[1] == 0.0, (foot, theta)


def test_a_gait_that_never_lifts_never_lands() -> None:
    assert swing_phase_left(1.0, 1.0, 0) == math.inf
    assert swing_phase_left(1.0, -1.2, 1) == math.inf


def test_a_step_in_reach_comes_at_the_gaits_own_time() -> None:
    """1 cm forward and 0.5 cm right now, 0.15 s to touchdown: the foot lands
    xi0 e^(w0 T) out (by hand: e^(6.5308 x 0.15) = 2.6635)."""
    plan = plan_step((0.01, -0.005), w0=W0, t_nominal=0.15, t_min=0.05, reach=WIDE)
    grow = 2.6635
    assert math.exp(W0 * 0.15) == pytest.approx(grow, rel=1e-4)
    assert plan.t_s == 0.15
    assert (plan.dx, plan.dy) == pytest.approx((0.01 * grow, -0.005 * grow), rel=1e-4)
    assert tempo_for(0.15, plan.t_s) == 0.0


@pytest.mark.parametrize(("dxi", "side"), [((0.03, 0.0), "forward"), ((-0.03, 0.0), "back"),
                                           ((0.0, 0.03), "left"), ((0.0, -0.03), "right")])
def test_out_of_reach_the_step_comes_sooner_on_the_errors_side(
        dxi: tuple[float, float], side: str) -> None:
    """3 cm with 4 cm of reach that way (the others wide): the step comes when
    3 e^(w0 T) = 4 cm, T = ln(4/3) / w0 = 44.0 ms (by hand), and lands at the reach."""
    reach = WIDE._replace(**{side: 0.04})
    plan = plan_step(dxi, w0=W0, t_nominal=0.3, t_min=0.01, reach=reach)
    assert plan.t_s == pytest.approx(0.04405, abs=1e-4)
    assert math.hypot(plan.dx, plan.dy) == pytest.approx(0.04)
    assert (plan.dx * dxi[0], plan.dy * dxi[1]) >= (0.0, 0.0)        # toward the fall
    assert tempo_for(0.3, plan.t_s) == pytest.approx(0.3 / 0.04405 - 1.0, rel=1e-3)


def test_the_margin_lets_the_centre_of_pressure_take_the_rest() -> None:
    """With 1 cm of margin under the foot, a 4 cm reach fits 5 cm: T = ln(5/3) / w0."""
    reach = WIDE._replace(forward=0.04)
    plan = plan_step((0.03, 0.0), w0=W0, t_nominal=0.3, t_min=0.01, reach=reach,
                     margin=0.01)
    assert plan.t_s == pytest.approx(math.log(5 / 3) / W0)
    assert plan.dx == 0.04


def test_no_room_inward_steps_at_the_shortest_swing() -> None:
    """A foot already at the other foot (no inward room) cannot fit any inward error:
    the step comes at t_min, clipped to 0 inward."""
    reach = WIDE._replace(left=0.0)
    plan = plan_step((0.0, 0.01), w0=W0, t_nominal=0.3, t_min=0.2, reach=reach)
    assert plan.t_s == 0.2 and plan.dy == 0.0


def test_no_error_no_change() -> None:
    plan = plan_step((0.0, 0.0), w0=W0, t_nominal=0.3, t_min=0.2, reach=WIDE)
    assert (plan.t_s, plan.dx, plan.dy) == (0.3, 0.0, 0.0)
    assert tempo_for(math.inf, 0.1) == 0.0 and tempo_for(0.3, math.inf) == 0.0
