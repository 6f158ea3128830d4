"""A push in CI: the suite's 1 N*s backward push a quarter cycle into the step, walked as
`biped walk --push ... --stop-on-fall` walks it (robot.tuning.robustness.run_condition),
on the Dynamixel robot with the `walk` preset. Open loop it falls; with the robot file's
balance (capture step, brace, hold) it walks on (docs/robustness.md, the push grid). A
pushed run that a servo fault stops early is not counted as survived, nor one that stays
up by bracing and standing still."""

from __future__ import annotations

import pytest

from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.config.world import PUSH_NS, Push, World
from robot.tuning.conditions import AFTER_PUSH_S, WALK_ON_SHARE, Condition, push_grid
from robot.tuning.robustness import WalkJob, judge, run_condition

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
    # With the capture step at the gain the robot file had for the old law, and its brace
    # as it was before issue 32 (2.3 cm): the case this test needs, a run the watchdog stops.
    params = load_gait("robust").for_robot(load_robot(ROBOT)).replace(
        {"bal_step_gain": 0.238, "bal_brace_xi": 0.023})
    cond = next(c for c in push_grid(params.cycle_s, PUSH_NS)
                if c.name == f"push {PUSH_NS:g} N*s left at phase 0.5")
    assert cond.world is not None
    out = run_condition(WalkJob(ROBOT, "robust", params,
                                cond.world.pushes[0].at_s + AFTER_PUSH_S, cond))
    assert out.summary["stop_reason"].startswith("watchdog"), out.summary["stop_reason"]
    assert "overload" in out.summary["stop_reason"]
    assert out.fell is True and out.summary.get("fell") is False


def test_a_pushed_run_that_stands_still_does_not_count() -> None:
    """7 s walks (the push at 5 s): the flat walk, a light push to the left that the walk
    shrugs off, and the same push with a brace that never lets go (over 1 mm of
    capture-point error, held 3 s: the robot stands from when the rhythm is learned, about
    4.4 s in). Both pushed runs stay up; only the one that walks on survives."""
    params = load_gait("walk").for_robot(load_robot(ROBOT))
    light = Condition("push left", "light push", World(pushes=(Push(5.0, 0.0, 0.3),)),
                      walk_on=True)
    braced = Condition("push left", "light push, braced", light.world,
                       changes=(("bal_brace_xi", 0.001), ("bal_brace_s", 3.0)), walk_on=True)
    runs = judge([run_condition(WalkJob(ROBOT, "walk", params, 7.0, c))
                  for c in (Condition("flat", "flat"), light, braced)])
    flat, walked, stood = runs
    assert all(o.error == "" and o.fell is False for o in runs)
    assert walked.speed_m_s >= WALK_ON_SHARE * flat.speed_m_s and walked.survived
    assert stood.speed_m_s < 0.75 * flat.speed_m_s and stood.stood and not stood.survived
