"""A swing's timing and its level on a staircase (robot.gait.stair_steps): when a foot
lifts and lands in the gait's phase (eq 8 and its anti-phase), and the level a swing
carries its foot over between two levels: up early, down late."""

from __future__ import annotations

import math

#: A step up is climbed over this share of the swing's phase, from lift-off.
RISE_END = 0.4
#: A step down is descended from this share of the swing's phase to touchdown.
DROP_START = 0.7


def smooth(u: float) -> float:
    """Minimum-jerk 0 -> 1 over ``u`` in [0, 1] (clipped outside)."""
    u = min(max(u, 0.0), 1.0)
    return u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)


def swing_end(theta: float, delta_f: float, right: bool) -> float:
    """The phase [rad] at which the swing going on at ``theta`` ends: the right foot lifts
    while sin(theta) > -delta_f, the left while sin(theta) < delta_f (eq 8 and its
    anti-phase), so they land at pi - asin(-delta_f) and 2 pi - asin(-delta_f) (mod 2 pi),
    the first such phase after ``theta``."""
    land = (math.pi if right else 2.0 * math.pi) - math.asin(min(max(-delta_f, -1.0), 1.0))
    base = theta - math.fmod(theta, 2.0 * math.pi)
    end = base + land
    while end <= theta:
        end += 2.0 * math.pi
    while end - 2.0 * math.pi > theta:
        end -= 2.0 * math.pi
    return end


def lift_off_after(theta: float, delta_f: float, right: bool) -> float:
    """The phase [rad] of the first lift-off of that foot after ``theta``: the right foot
    lifts where sin(theta) rises through -delta_f, the left where it falls through
    delta_f (asin(-delta_f) and pi + asin(-delta_f), mod 2 pi)."""
    return swing_end(theta, delta_f, right) - math.pi + 2.0 * math.asin(
        min(max(-delta_f, -1.0), 1.0))


def ground_at(u: float, start: float, end: float) -> float:
    """The ground level [m] a swing from ``start`` to ``end`` [m] carries its foot over at
    phase share ``u``: up early (``RISE_END``), down late (``DROP_START``)."""
    if end > start:
        return start + (end - start) * smooth(u / RISE_END)
    if end < start:
        return start + (end - start) * smooth((u - DROP_START) / (1.0 - DROP_START))
    return start
