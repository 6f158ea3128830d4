"""The `climb` preset's footstep planner (robot.gait.stairs, robot.gait.stair_steps), by
hand-computed cases: the staircase the user describes against the sim's boxes (a second,
differently written geometry), where a sole stands, the smallest footstep shift, when a
swing ends, the swing's level profile, and a whole walk up and down planned (no physics):
every planned sole wholly on one level of the sim's boxes."""

from __future__ import annotations

import math

import pytest

from robot.config.bundled import ROBOTS_DIR
from robot.config.gait_file import load_gait
from robot.config.params import GaitParams
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.gait.stair_swing import ground_at, smooth, swing_end
from robot.gait.stairs import StairPlan
from sim.mujoco.world_stairs import stair_boxes

ROBOT = load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")
# The suite's stairs with 25 cm treads: risers up at 0.30, 0.55, 0.80 m, the landing to
# 1.10 m, risers down at 1.10, 1.35, 1.60 m.
PLAN = StairPlan(rise=0.015, count=3, tread=0.25, x0=0.30, landing=0.30)
BACK, FRONT = 0.05, 0.08    # the 18-joint robots' sole behind / ahead of the ankle [m]


def box_ground(x: float) -> float:
    """The sim's stairs: the top of the highest box over ``x`` (0: the floor)."""
    tops = [b.z1 for b in stair_boxes(0.015, 3, 0.25) if b.x0 < x < b.x1]
    return max(tops, default=0.0)


def test_the_plan_is_the_sims_staircase() -> None:
    assert PLAN.edges() == pytest.approx((0.30, 0.55, 0.80, 1.10, 1.35, 1.60))
    for i in range(-10, 200):
        x = i * 0.01 + 0.005          # off the edges
        assert PLAN.ground(x) == pytest.approx(box_ground(x), abs=1e-12), x


def test_the_plan_comes_from_the_parameters() -> None:
    assert StairPlan.of(GaitParams()) is None                          # none by default
    assert StairPlan.of(GaitParams(stairs_count=3.0)) is None          # no rise
    assert StairPlan.of(GaitParams(stairs_rise=0.015)) is None         # no steps
    p = GaitParams(stairs_rise=0.02, stairs_count=2.0, stairs_tread=0.3, stairs_x0=0.4,
                   stairs_landing=0.5)
    assert StairPlan.of(p) == StairPlan(0.02, 2, 0.3, 0.4, 0.5)


@pytest.mark.parametrize(("ankle", "stands"), [
    (0.20, True),     # on the floor, the toe (0.28) 2 cm short of the riser
    (0.215, False),   # the toe within 1 cm of the riser: it would rest on the nosing
    (0.32, True),     # on the 1st tread 2 cm past the riser, the heel over the floor
    (0.305, False),   # the ankle within 1 cm of the riser
    (1.08, True),     # on the landing, the toe over the tread below
    (1.14, False),    # below the landing with the heel on its nosing
    (1.165, True),    # heel 1.5 cm past the riser down
])
def test_a_sole_stands_on_the_level_under_its_ankle(ankle: float, stands: bool) -> None:
    assert PLAN.stands(ankle, BACK, FRONT, 0.01) is stands


def test_the_smallest_shift_that_makes_a_sole_stand() -> None:
    # The ankle 5 cm before the first riser: its toe would be 3 cm onto the tread.
    # Back 4 cm: toe 1 cm short of the riser; forward 6 cm: the ankle 1 cm past it.
    assert PLAN.placement(0.25, BACK, FRONT, 0.01, 0.12) == pytest.approx(-0.04)
    assert PLAN.placement(0.25, BACK, FRONT, 0.01, 0.12, least=0.0) == pytest.approx(0.06)
    assert PLAN.placement(0.25, BACK, FRONT, 0.01, 0.05, least=0.0) == 0.0  # out of reach
    assert PLAN.placement(0.45, BACK, FRONT, 0.01, 0.12) == 0.0           # stands already


def test_a_margin_behind_the_ankle_for_a_step_that_lands_short() -> None:
    # 2.5 cm past the riser: enough for 1 cm behind, not for 3 cm
    assert PLAN.stands(0.325, BACK, FRONT, 0.01)
    assert not PLAN.stands(0.325, BACK, FRONT, 0.01, behind=0.03)
    # from 5 cm before the riser, forward to 3 cm past it: 8 cm
    assert PLAN.placement(0.25, BACK, FRONT, 0.01, 0.12, least=0.0,
                          behind=0.03) == pytest.approx(0.08)


def test_the_pelvis_goes_over_the_part_of_the_sole_that_rests() -> None:
    # ankle 2 cm past the riser up: the sole rests from the riser (0.30) to the toe (0.40),
    # its middle 0.35 against the sole's 0.335
    assert PLAN.support_shift(0.32, BACK, FRONT) == pytest.approx(0.015)
    # ankle 2 cm before the riser down: it rests from the heel (1.03) to the edge (1.10)
    assert PLAN.support_shift(1.08, BACK, FRONT) == pytest.approx(-0.03)
    assert PLAN.support_shift(0.45, BACK, FRONT) == 0.0      # all of it on a tread


def test_a_swing_ends_where_its_lift_does() -> None:
    """Right lifts while sin(theta) > -delta_f, left while sin(theta) < delta_f."""
    d = -0.4
    right_end, left_end = math.pi - math.asin(0.4), 2 * math.pi - math.asin(0.4)
    assert swing_end(0.5, d, True) == pytest.approx(right_end)
    assert swing_end(2 * math.pi + 0.5, d, True) == pytest.approx(2 * math.pi + right_end)
    assert swing_end(3.5, d, False) == pytest.approx(left_end)
    assert math.sin(right_end) == pytest.approx(0.4)


def test_a_swing_climbs_early_and_descends_late() -> None:
    assert smooth(0.5) == 0.5 and smooth(-1.0) == 0.0 and smooth(2.0) == 1.0
    # up 1.5 cm: half way at u = 0.2, all of it by u = 0.4 (RISE_END)
    assert ground_at(0.2, 0.0, 0.015) == pytest.approx(0.0075)
    assert ground_at(0.4, 0.0, 0.015) == pytest.approx(0.015)
    # down 1.5 cm: still up at u = 0.7 (DROP_START), half way at 0.85, down at touchdown
    assert ground_at(0.7, 0.015, 0.0) == pytest.approx(0.015)
    assert ground_at(0.85, 0.015, 0.0) == pytest.approx(0.0075)
    assert ground_at(1.0, 0.015, 0.0) == pytest.approx(0.0)


def test_no_staircase_ahead_leaves_the_gait_as_it_was() -> None:
    """A staircase 5 m away: the planner is on and moves nothing for 4 s of walking."""
    p = load_gait("climb").for_robot(ROBOT)
    far = p.replace({"stairs_x0": 5.0})
    plain = p.replace({"stairs_count": 0.0})
    a, b = GaitEngine(ROBOT, far), GaitEngine(ROBOT, plain)
    a.start()
    b.start()
    for _ in range(800):
        assert a.tick(0.005) == pytest.approx(b.tick(0.005), abs=1e-12)
    assert a.stairs is not None and len(a.stairs.steps) >= 4


def test_the_planned_footsteps_go_up_and_down_wholly_on_the_treads() -> None:
    """The climb preset on the Dynamixel robot, 40 s of gait ticks (no physics): each
    planned sole lies on one level of the sim's boxes with 1 cm to spare, at the height the
    plan gives it, and the footsteps go up the three steps and down again to the floor."""
    p = load_gait("climb").for_robot(ROBOT)
    eng = GaitEngine(ROBOT, p)
    eng.start()
    for _ in range(4000):      # 100 Hz
        eng.tick(0.01)
    assert eng.stairs is not None
    steps = eng.stairs.steps
    for _, x, level in steps:
        under = [box_ground(x + s * 0.001) for s in range(-60, 91)]   # heel - 1 cm .. toe + 1 cm
        assert max(under) == pytest.approx(level, abs=1e-12), (x, level)
        assert box_ground(x) == pytest.approx(level, abs=1e-12), (x, level)
    levels = [round(level, 4) for _, _, level in steps]
    assert 0.045 in levels and levels[-1] == 0.0
    first_top = levels.index(0.045)
    assert levels[:first_top] == sorted(levels[:first_top])            # up, then
    assert levels[first_top:] == sorted(levels[first_top:], reverse=True)  # down
    assert max(x for _, x, _ in steps) > 1.65                          # past the stairs


def test_the_planner_goes_when_the_staircase_does() -> None:
    """The staircase set to 0 steps mid-walk (the panel, a preset switch): the planner
    and its phase rate go with it, and the gait is the plain one again."""
    p = load_gait("climb").for_robot(ROBOT)
    eng = GaitEngine(ROBOT, p)
    eng.start()
    for _ in range(200):
        eng.tick(0.005)
    assert eng.stairs is not None
    eng.replace_params(p.replace({"stairs_count": 0.0}))
    for _ in range(2000):                  # the live value follows the set one
        eng.tick(0.005)
        if eng.live_params.stairs_count == 0.0:
            break
    assert eng.live_params.stairs_count == 0.0 and eng.stairs is None


def test_a_riser_is_crossed_from_two_feet_side_by_side() -> None:
    """Closing steps (stairs_close): before each riser up both feet stand side by side,
    their toes 1 cm short of the riser (ankle at riser - 8 cm toe - 1 cm: 0.21, 0.46,
    0.71 m), and the next footstep crosses from there to the ankle 1 cm past it (0.31,
    0.56, 0.81 m). The swing that crosses is then the crossing (10 cm up, 5 cm heel + 1 + 1 cm
    margins = 7 cm down) plus at most STEP_AHEAD (2 cm) the gait left the crossing foot
    behind the other; without closing steps it also carries the gait's step (a 15.8 cm
    swing up the first riser, 10.1 cm down the first riser down)."""
    p = load_gait("climb").for_robot(ROBOT)
    assert p.stairs_close > 0.0
    eng = GaitEngine(ROBOT, p)
    eng.start()
    for _ in range(4000):      # 100 Hz, 40 s
        eng.tick(0.01)
    assert eng.stairs is not None
    steps = eng.stairs.steps
    xs = [round(x, 6) for _, x, _ in steps]
    for short, past in ((0.21, 0.31), (0.46, 0.56), (0.71, 0.81)):
        k = xs.index(past)
        assert xs[k - 2:k] == pytest.approx([short, short], abs=1e-6)   # side by side
        assert steps[k - 2][0] != steps[k - 1][0]
    last: dict[bool, tuple[float, float]] = {}
    levels = [0.0]
    for right, x, level in steps:
        if level != levels[-1]:        # the first foot onto another level: the crossing
            levels.append(level)
            travel = x - last[right][0]
            limit = (0.10 if level > last[right][1] else 0.07) + 0.02
            assert 0.0 < travel <= limit + 1e-9, (x, level, travel)
        last[right] = (x, level)
    assert len(levels) == 7      # the floor, three levels up, two down, the floor
