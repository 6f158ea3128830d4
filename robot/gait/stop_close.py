"""A stop that finishes its step: the envelope's ramp-out as a feedback loop asks for it
(``BodyTrim.close``, the balance stage's ``bal_stop_close``), instead of the stride
shrinking over ``ramp_cycles``.

A walk told to stop keeps its full stride until the swing in progress lands ("finish"),
then, in the next swing ("close"), the envelope falls from where it is to 0 within that
one swing: the foot in the air comes down beside the standing one and the walk ends on
both feet, side by side. While both feet are down the envelope holds (a stride changed
under two planted feet scrubs them and turns the body), but for the engine's slowest
ramp-out (ENVELOPE_MIN_RATE of its rate over ``ramp_cycles``: about 0.01 of the stride in
a double support), which ends a stop whose feet never lift again. Measured on the bundled robots
(docs/gait.md, "A stop that finishes its step"): the stride shrinking over three cycles
turned them by up to 2.1-5.8 deg by where in the step the stop came; the small last steps
drag the feet.
"""

from __future__ import annotations

import math

from robot.config.params import GaitParams

#: The closing swing's envelope reaches 0 this share into the swing, so that a faster or
#: slower phase (a feedback's tempo) still ends it before the foot lands.
CLOSE_SHARE = 0.9


def swing_share(p: GaitParams) -> float:
    """The share of a gait cycle one foot is in the air (the paper's lift: the right
    foot is up while sin(theta) + delta_f > 0): (pi + 2 asin(delta_f)) / (2 pi)."""
    d = min(max(p.delta_f, -1.0), 1.0)
    return (math.pi + 2.0 * math.asin(d)) / (2.0 * math.pi)


def ramp_out(stage: str | None, ramp: float, gait_dt: float, lifted: bool,
             p: GaitParams, *, least: float) -> tuple[str, float]:
    """One tick of a closing stop: the stage ("finish" while the swing in progress at the
    stop lands, then "close") and the envelope's ramp variable after ``gait_dt`` [s of
    gait time]; ``lifted``: a foot is in the air now; ``stage`` None on the stop's first
    tick. ``least``: what the ramp falls by in any case (the engine's slowest ramp-out, so
    that a stop whose feet never lift again, a robot held braced on the ground, still
    ends)."""
    if stage is None:
        stage = "finish" if lifted else "close"
    if stage == "finish":
        return ("finish" if lifted else "close"), max(0.0, ramp - least)
    if not lifted:
        return stage, max(0.0, ramp - least)
    swing = CLOSE_SHARE * swing_share(p) * p.cycle_s
    step = 1.0 if not math.isfinite(swing) or swing <= 0.0 else gait_dt / swing
    return stage, max(0.0, ramp - max(step, least))
