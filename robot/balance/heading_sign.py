"""Which way a 5-DoF robot's step lengths turn it, found while it walks: the heading
loop's turn trim steers legs without hip yaw by making one stride longer than the other
(robot.gait.targets, x ``bal_stride_turn``), and which way that turns the body depends on
the robot *and* the gait (docs/gait.md: on ROBOTIS MINI `walk` needs -1, `crouch` +1,
`robust` turned 138 deg in a minute with -1). A wrong sign runs away: the heading error
grows while the trim pushes against it. So every CHECK_CYCLES gait cycles the loop looks
back: if at two looks running the error is over MIN_DEG and has grown by GROW_DEG or more
since the look before, the second time by no less than the first (it does not slow
down), while the trim pushes the way that should shrink it, the sign flips (and the
loop's integral and trim start again from 0). With the right sign an error may grow for
a while too, while the integral builds up after a disturbance, but slower and slower. A
robot with hip yaw never looks (its trim yaws the feet).
"""

from __future__ import annotations

import math
from typing import NamedTuple

CHECK_CYCLES = 2.0
MIN_DEG = 3.0
GROW_DEG = 1.0


class SignCheck(NamedTuple):
    """sign: +1 / -1 on the trim as the robot's stride steering turns it; since_s: time
    since the last look [s]; error: |heading error| then [rad]; flips: how many so far;
    grew: how much the error grew [rad] between the last two looks when it ran away,
    else 0."""

    sign: float = 1.0
    since_s: float = 0.0
    error: float = 0.0
    flips: int = 0
    grew: float = 0.0


def look(s: SignCheck, error: float, want: float, cycle_s: float, dt: float
         ) -> tuple[SignCheck, bool]:
    """One tick: the check after ``dt`` [s] with the heading ``error`` [rad] (reference
    less heading) and the loop's own output ``want`` [rad/step] (before the sign), for a
    gait cycle of ``cycle_s`` [s]; True when the sign flipped this tick."""
    since = s.since_s + dt
    if not (math.isfinite(cycle_s) and since >= CHECK_CYCLES * cycle_s):
        return s._replace(since_s=since), False
    size = abs(error)
    growth = size - s.error
    runaway = (size > math.radians(MIN_DEG) and growth >= math.radians(GROW_DEG)
               and want * error > 0.0)
    if runaway and s.grew > 0.0 and growth >= s.grew:
        return SignCheck(-s.sign, 0.0, size, s.flips + 1), True
    return SignCheck(s.sign, 0.0, size, s.flips, growth if runaway else 0.0), False
