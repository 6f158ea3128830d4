"""The gait's own rhythm in an IMU signal, learned per phase, so that feedback can act on
what the rhythm does not explain (a push, a bump) rather than on the walk's normal rocking.

A walking torso rocks in pitch and roll at the step frequency (in MuJoCo the bundled robots
swing +-0.9 rad/s in pitch every step with the open-loop walk). A controller that steps
toward the measured tilt rate would step on every one of those swings. ``Rhythm`` keeps,
for each signal, a table over the gait phase theta (mod 2 pi) in ``BINS`` bins with linear
interpolation, learned by an exponential average with a time constant given in gait
cycles. ``residual`` is the measurement minus the learned value at that phase.

Values are immutable (tuples): ``learn`` returns a new ``Rhythm``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

#: Phase bins per gait cycle: 64 bins = 0.1 rad of theta each (about 14 ms at 0.87 s per
#: cycle): linear interpolation follows a two-per-cycle swing to within about 1 %.
BINS = 64
#: Signals kept: torso roll, pitch [rad] and roll, pitch rate [rad/s].
SIGNALS = 4
_TWO_PI = 2.0 * math.pi
_ROWS = range(0, SIGNALS * BINS, BINS)  # where each signal's bins start in the table


def _bins(theta: float) -> tuple[int, int, float]:
    """The two bins around ``theta`` [rad] and the weight of the second."""
    x = (theta % _TWO_PI) / _TWO_PI * BINS
    i = int(x) % BINS
    return i, (i + 1) % BINS, x - math.floor(x)


class Rhythm(NamedTuple):
    """Per-phase means of the ``SIGNALS`` signals (row-major: signal * BINS + bin), the
    weight each bin has seen (in passes through it, at most the time constant) and the
    number of gait cycles learned so far."""

    table: tuple[float, ...] = (0.0,) * (SIGNALS * BINS)
    weight: tuple[float, ...] = (0.0,) * BINS
    cycles: float = 0.0

    def at(self, theta: float) -> tuple[float, ...]:
        """The learned value of every signal at phase ``theta`` [rad]."""
        i, j, w = _bins(theta)
        t, u = self.table, 1.0 - w
        return tuple([u * t[k + i] + w * t[k + j] for k in _ROWS])

    def residual(self, theta: float, values: tuple[float, ...]) -> tuple[float, ...]:
        """``values`` minus the learned rhythm at ``theta``."""
        return tuple(v - m for v, m in zip(values, self.at(theta), strict=True))

    def learn(self, theta: float, values: tuple[float, ...], dtheta: float,
              tau_cycles: float) -> Rhythm:
        """Move the two bins around ``theta`` toward ``values``. dtheta: phase advanced
        this tick [rad]; tau_cycles: time constant [gait cycles] (0: no learning).

        Each bin keeps a weighted mean of its samples: a running mean until it has seen
        ``tau_cycles`` passes' worth of weight, then an exponential one with that time
        constant. So a new walk is learned after one cycle, and an old one is forgotten
        in ``tau_cycles``."""
        if tau_cycles <= 0.0 or dtheta <= 0.0:
            return self
        i, j, w = _bins(theta)
        span = dtheta / _TWO_PI * BINS            # this tick in passes through a bin
        t = list(self.table)
        weight = list(self.weight)
        for b, wb in ((i, (1.0 - w) * span), (j, w * span)):
            if wb <= 0.0:
                continue
            weight[b] = min(weight[b] + wb, tau_cycles)
            rate = min(1.0, wb / weight[b])
            for a, v in zip(range(b, SIGNALS * BINS, BINS), values, strict=True):
                t[a] += rate * (v - t[a])
        return Rhythm(tuple(t), tuple(weight), self.cycles + dtheta / _TWO_PI)
