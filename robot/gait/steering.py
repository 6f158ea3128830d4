"""The steering budget: speed, turn and side step limited jointly (the gait's steering
parameters, robot/config/params.py)."""

from __future__ import annotations

import dataclasses

from robot.config.params import SPECS, GaitParams

#: Steering is limited jointly: each of speed, turn and side step may reach the end of
#: its range alone, but |speed| / its end + |turn| / its end + |side_step| / its end
#: may not exceed this; a combination beyond it is scaled down (all three alike). Measured
#: in MuJoCo with balance on: 1.25 walked every combination tried on both 18-joint robots
#: (30 s each), 1.5 fell on the Feetech one (speed 1.125 with turn 0.375, and backward
#: -0.75 with turn 0.375).
STEER_BUDGET = 1.25


def within_steering_budget(p: GaitParams) -> GaitParams:
    """``p`` with speed, turn and side_step scaled down together to ``STEER_BUDGET``
    (``p`` itself when inside it)."""
    used = 0.0
    for name in ("speed", "turn", "side_step"):
        v, spec = getattr(p, name), SPECS[name]
        end = spec.hi if v > 0 else -spec.lo
        used += abs(v) / end if end > 0 else 0.0
    if used <= STEER_BUDGET:
        return p
    k = STEER_BUDGET / used
    return dataclasses.replace(p, speed=p.speed * k, turn=p.turn * k, side_step=p.side_step * k)
