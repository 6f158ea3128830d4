"""The heading loop finds which way a 5-DoF robot's step lengths turn it
(robot.balance.heading_sign): a plant worked by hand, heading rate = k x the applied
trim, with k of either sign; the balance law itself closed around it."""

from __future__ import annotations

import math

import pytest

from robot.balance.heading_sign import CHECK_CYCLES, SignCheck, look
from robot.balance.law import NO_PHASE, Attitude, BalanceState, balance_step
from robot.config.gait_file import load_gait

WALK = load_gait("walk").params


def test_an_error_growing_at_two_looks_the_trim_pushes_against_flips_the_sign() -> None:
    cycle = WALK.cycle_s
    first, flipped = look(SignCheck(error=math.radians(2.5)), math.radians(4.0), 0.1, cycle,
                          CHECK_CYCLES * cycle)
    assert not flipped and first.grew == pytest.approx(math.radians(1.5))   # not yet
    s, flipped = look(first, math.radians(5.6), 0.1, cycle, CHECK_CYCLES * cycle)
    assert flipped and s.sign == -1.0 and s.flips == 1
    # Growing again but slower (1.2 deg after 1.5): the right sign catching up, no flip.
    slower, flipped = look(first, math.radians(5.2), 0.1, cycle, CHECK_CYCLES * cycle)
    assert not flipped and slower.sign == 1.0
    # Not before the look is due, not when small, not when it shrinks, not when the trim
    # pushes the other way (the error grows because the trim lets it).
    assert not look(SignCheck(error=0.07), 0.1, 0.1, cycle, 0.01)[1]
    assert not look(SignCheck(error=0.0), math.radians(2.5), 0.1, cycle, 2 * cycle)[1]
    assert not look(SignCheck(error=0.1), 0.09, 0.1, cycle, 2 * cycle)[1]
    assert not look(SignCheck(error=0.07), 0.1, -0.1, cycle, 2 * cycle)[1]


@pytest.mark.parametrize("k", [1.0, -1.0])
def test_the_law_holds_a_plant_of_either_sign(k: float) -> None:
    """Heading rate = k x 0.8 x the applied trim [rad/s per rad/step] plus a drift of
    3 deg/s: with k = +1 the loop holds it unflipped; with k = -1 it flips once and then
    holds it too (within 3 deg after 30 s; without the check it would run away)."""
    p = WALK.replace({"bal_stride_turn": 1.0})
    gait = NO_PHASE._replace(by_stride=True)
    state, heading, dt = BalanceState(), 0.0, 0.005
    for _ in range(int(30.0 / dt)):
        state, corr = balance_step(state, Attitude(0, 0, 0, 0, 0, heading), p, dt, gait)
        heading += (k * 0.8 * corr.turn + math.radians(3.0)) * dt
    assert state.sign.flips == (0 if k > 0 else 1)
    assert abs(math.degrees(heading)) < 3.0
