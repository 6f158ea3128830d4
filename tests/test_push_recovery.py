"""A push in CI: the suite's 1 N*s backward push a quarter cycle into the step, walked as
`biped walk --push ... --stop-on-fall` walks it (robot.tuning.robustness.run_condition),
on the Dynamixel robot with the `walk` preset. Open loop it falls; with the robot file's
balance (capture step, brace, hold) it walks on (docs/robustness.md, the push grid). And a
pushed run that a servo fault stops early is not counted as survived."""

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


def test_a_run_a_servo_fault_stops_is_not_survived() -> None:
    """`robust` on the Dynamixel robot with the capture step on, pushed left at half a
    cycle: the left knee's
    overload trips the servos' watchdog before the torso falls; the run stops there and
    the suite counts it as not survived (the servos went limp), not as a walk that went on."""
    # With the capture step at the gain the robot file had for the old law.
    params = load_gait("robust").for_robot(load_robot(ROBOT)).replace(
        {"bal_step_gain": 0.238})
    cond = next(c for c in push_grid(params.cycle_s, PUSH_NS)
                if c.name == f"push {PUSH_NS:g} N*s left at phase 0.5")
    assert cond.world is not None
    out = run_condition(WalkJob(ROBOT, "robust", params,
                                cond.world.pushes[0].at_s + AFTER_PUSH_S, cond))
    assert out.summary["stop_reason"].startswith("watchdog"), out.summary["stop_reason"]
    assert "overload" in out.summary["stop_reason"]
    assert out.fell is True and out.summary.get("fell") is False
