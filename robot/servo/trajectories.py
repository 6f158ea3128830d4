"""The trajectories ``biped identify record`` runs a servo through on a pendulum bench.

Each is a goal [rad] (0: the arm hanging down) and a torque enable as functions of the
time since its start [s], within ``amplitude`` [rad] of 0, starting at 0 at rest (the
recorder ramps the arm to 0 first), so no run snaps:

- ``sine_slow`` / ``sine_fast``: 0.5 Hz at the full amplitude, 2 Hz at half of it;
- ``chirp``: 0.2 Hz rising linearly to 2.5 Hz over the run, at 0.8 of it;
- ``steps``: a staircase of steps of 0.6 of it, each held 1 s (what the P gain does alone);
- ``lift_drop``: lift to 0.9 of it in 1 s (minimum jerk), hold, then torque off at
  0.45 of the run: the weight falls and swings on the gearbox's friction alone.

The sine and chirp amplitudes grow over their first ``FADE_S`` (a smooth start); every
log of the set has the same names at every gain (``identify fit`` holds out by name).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

FADE_S = 0.5


@dataclass(frozen=True)
class Trajectory:
    """name; goal(t) [rad]; enable(t): torque on; t in [0, duration] [s]."""

    name: str
    goal: Callable[[float], float]
    enable: Callable[[float], bool]


def _fade(t: float) -> float:
    return min(1.0, t / FADE_S) ** 2 * (3 - 2 * min(1.0, t / FADE_S))


def _always(t: float) -> bool:
    return True


def min_jerk(s: float) -> float:
    """The minimum-jerk blend 0 → 1 over s in [0, 1] (clipped outside)."""
    s = min(max(s, 0.0), 1.0)
    return s ** 3 * (10 - 15 * s + 6 * s * s)


def trajectories(amplitude: float, duration: float) -> tuple[Trajectory, ...]:
    """The set, each ``duration`` [s] long, within ``amplitude`` [rad] of 0."""
    a, d = amplitude, duration

    def sine(f: float, share: float) -> Callable[[float], float]:
        return lambda t: share * a * _fade(t) * math.sin(2 * math.pi * f * t)

    def chirp(t: float) -> float:
        f0, f1 = 0.2, 2.5
        phase = 2 * math.pi * (f0 * t + (f1 - f0) * t * t / (2 * d))
        return 0.8 * a * _fade(t) * math.sin(phase)

    def steps(t: float) -> float:
        levels = (0.0, 0.6, 0.0, -0.6, 0.0, 0.3, -0.3, 0.6)
        return a * levels[min(int(t), len(levels) - 1)]

    def lift(t: float) -> float:
        return 0.9 * a * min_jerk(t / 1.0)

    return (Trajectory("sine_slow", sine(0.5, 1.0), _always),
            Trajectory("sine_fast", sine(2.0, 0.5), _always),
            Trajectory("chirp", chirp, _always),
            Trajectory("steps", steps, _always),
            Trajectory("lift_drop", lift, lambda t: t < 0.45 * d))
