"""A push in CI: the suite's 1 N*s backward push a quarter cycle into the step, walked as
`biped walk --push ... --stop-on-fall` walks it (robot.tuning.robustness.run_condition),
on the Dynamixel robot with the `walk` preset. Open loop it falls; with the robot file's
balance (capture step, brace, hold) it walks on (docs/robustness.md, the push grid)."""

from __future__ import annotations

import pytest

from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.config.world import PUSH_NS
from robot.tuning.conditions import AFTER_PUSH_S, push_grid
from robot.tuning.robustness import WalkJob, run_condition

ROBOT = "biped18-dynamixel"


@pytest.mark.parametrize("balance", [True, False])
def test_a_backward_push_is_survived_with_balance_only(balance: bool) -> None:
    params = load_gait("walk").for_robot(load_robot(ROBOT))
    cond = next(c for c in push_grid(params.cycle_s, PUSH_NS)
                if c.name == f"push {PUSH_NS:g} N*s backward at phase 0.25")
    assert cond.world is not None
    at = cond.world.pushes[0].at_s
    out = run_condition(WalkJob(ROBOT, "walk", params, at + AFTER_PUSH_S, cond,
                                balance=balance))
    assert out.error == ""
    assert out.fell is (not balance), out.summary
    if not balance:
        assert out.fell_at_s is not None and at < out.fell_at_s < at + AFTER_PUSH_S
