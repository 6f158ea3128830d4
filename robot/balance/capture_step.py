"""Capture step: where and when the swinging foot lands after a push, inside the paper's
phase-locked gait (step placement with step-timing adaptation).

The model is the linear inverted pendulum's divergent component of motion, the capture
point xi = c + c' / omega0 (omega0 = sqrt(g / h); Pratt et al. 2006, "Capture point: a step
toward humanoid push recovery"; Englsberger et al. 2015, "Three-dimensional bipedal walking
control based on divergent component of motion"): with the centre of pressure at p,
xi' = omega0 (xi - p). A disturbance dxi (how far xi lies from where the gait's own
rhythm puts it, robot.balance.law) does not change p, so it grows as
dxi(t) = dxi0 e^(omega0 t). If the swinging foot lands dxi(T) further than the gait's own
footstep, xi stands to the new foot as the gait expects: one step captures the push and
the walk goes on (the step-location half of Khadiv et al. 2016, "Step timing adjustment:
a step toward generating robust gaits", Humanoids, and 2020, "Walking control based on step
timing adaptation", IEEE T-RO, with their cost weights replaced by hard bounds).

When that step is beyond the leg's reach (or on the far side of the standing foot, which
this foot cannot cross), the step comes sooner: the largest T <= the gait's own remaining
swing time for which the step fits, T = ln(reach / |dxi0|) / omega0, not below the
shortest swing the phase rate allows (the step-timing half of Khadiv et al.; in a
phase-locked gait the phase rate is the control, as in the capture steps of Missura and
Behnke, "Online learning of balance and the capture step", Humanoids 2014). The gait phase
then runs T_nom / T times faster until touchdown.

Pure functions of floats; units: m, s, rad. ``swing_phase_left`` reads the paper's foot
lift (eq 8, 11, 12 as mapped in robot/gait/targets.py): the right foot is up while
sin(theta) + delta_f > 0, the left one while sin(theta) < delta_f.
"""

from __future__ import annotations

import math
from typing import NamedTuple

_TWO_PI = 2.0 * math.pi


class Reach(NamedTuple):
    """How far the foot may land from the gait's own footstep [m]: back, forward (x),
    right, left (y), each >= 0."""

    back: float
    forward: float
    right: float
    left: float


class StepPlan(NamedTuple):
    """When and where: t_s, the time to touchdown [s]; dx, dy: the landing offset from
    the gait's own footstep [m] (forward, left)."""

    t_s: float
    dx: float
    dy: float


def swing_phase_left(theta: float, delta_f: float, foot: int) -> float:
    """The main phase [rad] from ``theta`` until foot ``foot`` (0 right, 1 left) next
    touches down, in [0, 2 pi); inf when the gait never lifts it (|delta_f| >= 1)."""
    if not -1.0 < delta_f < 1.0:
        return math.inf
    touchdown = math.asin(delta_f) + (math.pi if foot == 0 else 0.0)
    return (touchdown - theta) % _TWO_PI


def _fit_time(dxi: float, room: float, w0: float) -> float:
    """The longest time [s] after which dxi e^(w0 t) still fits in ``room`` (>= 0) on its
    side: inf for no error, -inf when the room is already too small."""
    if dxi == 0.0:
        return math.inf
    if room <= 0.0 or room < abs(dxi) * 1e-12:
        return -math.inf
    return math.log(room / abs(dxi)) / w0


def plan_step(dxi: tuple[float, float], *, w0: float, t_nominal: float, t_min: float,
              reach: Reach, margin: float = 0.0) -> StepPlan:
    """The capture step for a capture-point error ``dxi`` (forward, left) [m] now, with
    the pendulum's ``w0`` [1/s], the gait's own time to touchdown ``t_nominal`` [s], the
    shortest allowed ``t_min`` [s] and the foot's ``reach``.

    The step lands at dxi e^(w0 T), clipped to the reach, where T is ``t_nominal`` if the
    step then fits in the reach plus ``margin`` [m] (what the centre of pressure can still
    take under the foot), else the time at which it just fits, not below ``t_min``."""
    ex, ey = dxi
    room_x = (reach.forward if ex > 0.0 else reach.back) + margin
    room_y = (reach.left if ey > 0.0 else reach.right) + margin
    fit = min(_fit_time(ex, room_x, w0), _fit_time(ey, room_y, w0))
    t = max(t_min, min(t_nominal, fit))
    grow = math.exp(w0 * t) if math.isfinite(t) else 0.0
    dx = min(max(ex * grow, -reach.back), reach.forward)
    dy = min(max(ey * grow, -reach.right), reach.left)
    return StepPlan(t, dx, dy)


def tempo_for(t_nominal: float, t_s: float) -> float:
    """The phase speed-up [-] that makes a swing of ``t_nominal`` [s] at the gait's rate
    end after ``t_s`` [s]: t_nominal / t_s - 1 (0 when either is not a finite time)."""
    if not (math.isfinite(t_nominal) and math.isfinite(t_s)) or t_s <= 0.0:
        return 0.0
    return max(0.0, t_nominal / t_s - 1.0)
