"""Pure motion helpers shared by the streamer and the ``pose`` command: slew limiting and
smooth point-to-point ramps. Angles in rad, speeds in rad/s, times in s; arrays are ordered
like ``robot.joints``.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from robot.errors import ConfigError

FloatArray = npt.NDArray[np.float64]

#: Peak speed of the minimum-jerk profile relative to its mean speed (15/8).
MIN_JERK_PEAK = 1.875
#: Longest ramp [s]: a full turn (2 pi) at the slowest configurable joint speed (0.05 rad/s,
#: robot.config) takes 236 s; anything longer is a unit error, not a motion.
MAX_RAMP_S = 300.0
#: Most waypoints of one ramp: MAX_RAMP_S at 2000 Hz (the highest --rate), 18 joints
#: x 8 bytes x 600001 rows = 86 MB.
MAX_RAMP_STEPS = 600_000


def _speeds(max_speed: npt.ArrayLike, n: int) -> FloatArray:
    v = np.broadcast_to(np.asarray(max_speed, dtype=float), (n,)).copy()
    if not np.all(np.isfinite(v)) or np.any(v <= 0):
        raise ConfigError(f"max_speed: expected positive finite speeds [rad/s], got {v.tolist()}")
    return v


def slew_limit(q_prev: npt.ArrayLike, q_goal: npt.ArrayLike, max_speed: npt.ArrayLike,
               dt: float) -> FloatArray:
    """``q_goal`` moved no further than ``max_speed * dt`` from ``q_prev`` per joint
    (exactly ``q_goal`` where it is within reach).

    q_prev, q_goal: joint angles [rad]; max_speed: scalar or per joint [rad/s]; dt: [s] > 0.
    """
    prev = np.asarray(q_prev, dtype=float)
    goal = np.asarray(q_goal, dtype=float)
    if prev.shape != goal.shape:
        raise ConfigError(f"slew_limit: q_prev shape {prev.shape} != q_goal shape {goal.shape}")
    if not (dt > 0 and math.isfinite(dt)):
        raise ConfigError(f"slew_limit: dt must be a positive time [s], got {dt}")
    step = _speeds(max_speed, prev.size).reshape(prev.shape) * dt
    d = goal - prev
    return np.where(np.abs(d) <= step, goal, prev + np.clip(d, -step, step))


def min_jerk(s: npt.ArrayLike) -> FloatArray:
    """Minimum-jerk progress 10s³ - 15s⁴ + 6s⁵ for normalised time ``s`` in [0, 1]."""
    x = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
    return x * x * x * (10.0 + x * (-15.0 + 6.0 * x))


def ramp_duration(q_from: npt.ArrayLike, q_to: npt.ArrayLike, max_speed: npt.ArrayLike, *,
                  min_duration: float = 0.5) -> float:
    """Shortest minimum-jerk duration [s] whose peak speed stays within ``max_speed``."""
    a = np.asarray(q_from, dtype=float).ravel()
    b = np.asarray(q_to, dtype=float).ravel()
    if a.shape != b.shape:
        raise ConfigError(f"ramp: q_from has {a.size} joints, q_to has {b.size}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ConfigError("ramp: q_from and q_to must be finite angles [rad]")
    v = _speeds(max_speed, a.size)
    need = float(np.max(MIN_JERK_PEAK * np.abs(b - a) / v)) if a.size else 0.0
    duration = max(float(min_duration), need)
    if not duration <= MAX_RAMP_S:
        raise ConfigError(f"ramp: would last {duration:.3g} s (joint speeds down to "
                          f"{float(np.min(v)) if v.size else 0:.3g} rad/s); expected at most "
                          f"{MAX_RAMP_S:g} s: raise the speed or check its unit")
    return duration


def ramp(q_from: npt.ArrayLike, q_to: npt.ArrayLike, max_speed: npt.ArrayLike,
         rate_hz: float, *, min_duration: float = 0.5) -> FloatArray:
    """Waypoints from ``q_from`` to ``q_to`` at ``rate_hz``, minimum-jerk in time.

    Returns shape (n + 1, joints): row 0 is exactly ``q_from``, the last row exactly
    ``q_to``, and no joint moves more than ``max_speed / rate_hz`` [rad] between rows.
    Lasts at least ``min_duration`` [s] so that tiny moves are gentle too.
    """
    if not (rate_hz > 0 and math.isfinite(rate_hz)):
        raise ConfigError(f"ramp: rate_hz must be a positive rate [Hz], got {rate_hz}")
    if not min_duration >= 0:
        raise ConfigError(f"ramp: min_duration must be >= 0 [s], got {min_duration}")
    a = np.asarray(q_from, dtype=float).ravel()
    b = np.asarray(q_to, dtype=float).ravel()
    duration = ramp_duration(a, b, max_speed, min_duration=min_duration)
    # Whole steps; rounding up only lowers the peak speed.
    n = max(1, math.ceil(duration * rate_hz - 1e-9))
    if n > MAX_RAMP_STEPS:
        raise ConfigError(f"ramp: {duration:.3g} s at {rate_hz:g} Hz is {n} steps; expected "
                          f"at most {MAX_RAMP_STEPS}: lower the rate")
    s = min_jerk(np.arange(n + 1) / n)
    path = a + np.outer(s, b - a)
    path[0] = a
    path[-1] = b
    return path
