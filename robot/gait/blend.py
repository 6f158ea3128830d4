"""How the gait's live parameters follow a change while it walks: a slider's first-order
follow, the steering's rate limit, and a preset switch's blend.

The paper's open point is the transition between two of its gaits. Its phase rates are
integrated (robot.gait.expressions.advance), so a rate never jumps the phase; the
amplitudes (stride, lift, crouch, sway, ...) would step the targets, so they move:

- after a slider change (``GaitEngine.set_params``): first order with ``PARAM_TAU_S``;
- after a preset switch (``GaitEngine.blend_to``): every shaping parameter along one
  minimum-jerk blend from the values live at the switch to the new preset's, over
  ``PRESET_BLEND_S``: the blend starts and ends with zero rate, and its fastest rate is
  1.875 / PRESET_BLEND_S of the gap (a first-order follow starts at its fastest,
  1 / PARAM_TAU_S = 10 per second). Measured in MuJoCo: ``walk`` -> ``jog`` ->
  ``crouch`` -> ``walk`` on both 18-joint robots, docs/gait.md "Switching presets live";
- steering (``speed``, ``turn``, ``side_step``) always at ``STEER_RATE``, blend or not.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from robot.config.params import SPECS, GaitParams

#: Time constant [s] with which live parameter changes are followed while the gait runs.
#: Phase rates are integrated, but amplitudes (stride, foot height, ...) would otherwise
#: step the targets within one tick.
PARAM_TAU_S = 0.1
#: Steering parameters follow a live change at most this fast [unit/s]: a reversal or a
#: sudden side step or turn would otherwise change the step under a foot that stands.
#: (speed: stride multiplier per s; turn: rad/step per s; side_step: m/step per s)
STEER_RATE: dict[str, float] = {"speed": 0.5, "turn": 0.25, "side_step": 0.02}
#: A preset switch blends every shaping parameter over this long [s] (module docstring):
#: about one and a half `walk` cycles, two `jog` cycles.
PRESET_BLEND_S = 1.2


def min_jerk(x: float) -> float:
    """The minimum-jerk blend weight 10 x^3 - 15 x^4 + 6 x^5 on x clipped to [0, 1]: 0 and
    1 at the ends with zero rate and acceleration; fastest rate 1.875 at x = 0.5."""
    x = min(max(x, 0.0), 1.0)
    return x * x * x * (10.0 + x * (-15.0 + 6.0 * x))


@dataclass(frozen=True)
class Blend:
    """A preset switch: from ``start`` (the parameters live at the switch) to ``end`` over
    ``seconds`` [s] > 0."""

    start: GaitParams
    end: GaitParams
    seconds: float = PRESET_BLEND_S

    def __post_init__(self) -> None:
        if not (math.isfinite(self.seconds) and self.seconds > 0.0):
            raise ValueError(f"Blend.seconds: expected a positive time [s], got "
                             f"{self.seconds!r}")

    def value(self, name: str, t: float) -> float:
        """Parameter ``name`` at ``t`` [s] after the switch (``end``'s exactly from
        ``seconds`` on)."""
        a, b = getattr(self.start, name), getattr(self.end, name)
        if t >= self.seconds:
            return float(b)
        return float(a + min_jerk(t / self.seconds) * (b - a))


def follow(live: GaitParams, target: GaitParams, dt: float, *,
           blend: Blend | None = None, blend_t: float = 0.0) -> GaitParams:
    """``live`` moved ``dt`` [s] towards ``target``: steering at ``STEER_RATE``, the rest
    along ``blend`` at ``blend_t`` [s] after its start (its end must be ``target``), or
    first order (``PARAM_TAU_S``) without one; ``target`` itself once reached."""
    if live is target:
        return live
    a = 1.0 - math.exp(-dt / PARAM_TAU_S)
    moved: dict[str, float] = {}
    for name, spec in SPECS.items():
        cur, goal = getattr(live, name), getattr(target, name)
        if cur != goal:
            rate = STEER_RATE.get(name)
            if rate is not None:
                step = rate * dt
                v = goal if abs(goal - cur) <= step else cur + math.copysign(step, goal - cur)
                moved[name] = v
                continue
            if blend is not None:
                moved[name] = blend.value(name, blend_t)
                continue
            v = cur + a * (goal - cur)
            moved[name] = goal if abs(goal - v) <= 1e-9 * (spec.hi - spec.lo) else v
    return target if all(moved[n] == getattr(target, n) for n in moved) \
        else dataclasses.replace(live, **moved)
