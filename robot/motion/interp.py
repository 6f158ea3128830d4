"""Interpolation of keyframes (times, values) for smooth joint motion, vectorised.

- ``min_jerk``: each segment is the minimum-jerk profile between its two keyframes
  (Flash & Hogan 1985: q = q0 + (q1 - q0)(10 s^3 - 15 s^4 + 6 s^5), s the segment's
  normalised time): zero velocity and acceleration at every keyframe, never beyond the
  two keyframes of the segment, peak speed 1.875 x the segment's mean speed.
- ``smooth``: the monotone piecewise-cubic Hermite interpolant (Fritsch & Carlson 1980,
  with the harmonic-mean slopes of Fritsch & Butland 1984): continuous velocity, passes
  through the keyframes without stopping, never overshoots them (no value outside the
  range of the two keyframes of a segment), zero slope at local extrema.

Before the first keyframe the first value holds, after the last one the last value.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from robot.motion import ramp

Array = npt.NDArray[np.float64]
METHODS = ("min_jerk", "smooth")


def _segment(times: Array, t: Array) -> tuple[npt.NDArray[np.intp], Array, Array]:
    """Segment index, its start time and its duration for each of ``t`` (clamped)."""
    i = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    return i, times[i], times[i + 1] - times[i]


def min_jerk(times: Array, values: Array, t: Array) -> Array:
    """values: (k, j) keyframes; t: (n,) → (n, j)."""
    times, values, t = np.asarray(times, float), np.asarray(values, float), np.asarray(t, float)
    if len(times) == 1:
        return np.repeat(values[:1], len(t), axis=0)
    i, t0, h = _segment(times, t)
    return values[i] + (values[i + 1] - values[i]) * ramp.min_jerk((t - t0) / h)[:, None]


def _slopes(times: Array, values: Array) -> Array:
    """Fritsch-Butland slopes at the keyframes (k, j): 0 at extrema and flat segments."""
    h = np.diff(times)[:, None]
    delta = np.diff(values, axis=0) / h
    m = np.zeros_like(values)
    if len(times) == 2:
        m[:] = delta  # one segment: the straight line is monotone
        return m
    d0, d1 = delta[:-1], delta[1:]
    h0, h1 = h[:-1], h[1:]
    same = (d0 * d1) > 0
    w0, w1 = 2.0 * h1 + h0, h1 + 2.0 * h0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        inner = (w0 + w1) / (w0 / d0 + w1 / d1)
    m[1:-1] = np.where(same, inner, 0.0)
    # Ends: the one-sided three-point estimate, kept monotone (Fritsch-Carlson).
    for end, (dn, dnn, hn, hnn) in ((0, (delta[0], delta[1], h[0], h[1])),
                                    (-1, (delta[-1], delta[-2], h[-1], h[-2]))):
        est = ((2.0 * hn + hnn) * dn - hn * dnn) / (hn + hnn)
        est = np.where(np.sign(est) != np.sign(dn), 0.0, est)
        est = np.where((np.sign(dn) != np.sign(dnn)) & (np.abs(est) > 3 * np.abs(dn)),
                       3.0 * dn, est)
        m[end] = est
    return m


def smooth(times: Array, values: Array, t: Array) -> Array:
    """values: (k, j) keyframes; t: (n,) → (n, j)."""
    times, values, t = np.asarray(times, float), np.asarray(values, float), np.asarray(t, float)
    if len(times) == 1:
        return np.repeat(values[:1], len(t), axis=0)
    m = _slopes(times, values)
    i, t0, h = _segment(times, t)
    s = np.clip((t - t0) / h, 0.0, 1.0)[:, None]
    hh = h[:, None]
    s2, s3 = s * s, s * s * s
    return ((2 * s3 - 3 * s2 + 1) * values[i] + (s3 - 2 * s2 + s) * hh * m[i]
            + (-2 * s3 + 3 * s2) * values[i + 1] + (s3 - s2) * hh * m[i + 1])


def interpolate(method: str, times: Array, values: Array, t: Array) -> Array:
    return (min_jerk if method == "min_jerk" else smooth)(times, values, t)
