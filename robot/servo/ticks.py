"""Tick arithmetic: joint angles [rad] ↔ servo ticks, and the tick range a joint's limits
allow. Pure numpy over arrays in joint order; the servo map (robot/bus/servo_map.py), the
bus's limit check (robot/bus/limits.py) and the robot file's checks (robot/config/checks.py)
all compute with these, so "the file loads" and "the bus accepts every goal the map can
produce" cannot drift apart.

ticks = zero + sign * q * ticks_per_rad (ticks_per_rad = resolution / span).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

Floats = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]

#: Slack [ticks] so a limit that lands on a whole tick up to float rounding keeps that tick.
ROUNDING_SLACK = 1e-9


def tick_range(zero: Floats, sign: Floats, ticks_per_rad: Floats, q_min: Floats,
               q_max: Floats) -> tuple[Ints, Ints]:
    """The whole ticks inside [q_min, q_max] [rad] per joint: (lowest, highest) [ticks].
    Empty (lowest > highest) when the limits hold no whole tick."""
    a = zero + sign * q_min * ticks_per_rad
    b = zero + sign * q_max * ticks_per_rad
    lo = np.ceil(np.minimum(a, b) - ROUNDING_SLACK).astype(np.int64)
    hi = np.floor(np.maximum(a, b) + ROUNDING_SLACK).astype(np.int64)
    return lo, hi


def accepted_range(lo: Ints, hi: Ints, resolution: Floats | Ints) -> tuple[Ints, Ints]:
    """``tick_range`` cut to the ticks the servo has (0 .. resolution - 1) [ticks]."""
    top = np.asarray(resolution).astype(np.int64) - 1
    return np.maximum(lo, 0), np.minimum(hi, top)


def to_rad(ticks: npt.ArrayLike, zero: Floats, sign: Floats, ticks_per_rad: Floats) -> Floats:
    """Ticks → joint angles [rad] (not clamped: a read-back may be outside the limits)."""
    out: Floats = (np.asarray(ticks, dtype=float) - zero) * sign / ticks_per_rad
    return out
