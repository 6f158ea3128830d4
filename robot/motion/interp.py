"""Interpolation of keyframes (times, values) for smooth joint motion, vectorised.

- ``min_jerk``: each segment is the minimum-jerk profile between its two keyframes
  (Flash & Hogan 1985: q = q0 + (q1 - q0)(10 s^3 - 15 s^4 + 6 s^5), s the segment's
  normalised time): zero velocity and acceleration at every keyframe, never beyond the
  two keyframes of the segment, peak speed 1.875 x the segment's mean speed.
- ``smooth``: the monotone piecewise-cubic Hermite interpolant (Fritsch & Carlson 1980,
  with the harmonic-mean slopes of Fritsch & Butland 1984): continuous velocity, passes
  through the keyframes without stopping, never overshoots them (no value outside the
  range of the two keyframes of a segment), zero slope at local extrema. For sparse
  keyframes (a hand's, a glTF's cubic or step track).
- ``spline``: the C2 cubic spline through samples with not-a-knot ends (de Boor, *A
  Practical Guide to Splines*, ch. IV): continuous acceleration, exact on any cubic,
  error O(h^4) on a smooth curve, so it recovers a peak that falls between two frames of
  a sampled animation (BVH frames, a glTF's sampled or linear track). It may overshoot
  where the samples turn sharply; ``spline(..., lo=, hi=)`` keeps it inside the joint
  limits wherever the two samples of a segment are (a limit the samples cross is not
  hidden). Fewer than four samples: ``smooth``.

Before the first keyframe the first value holds, after the last one the last value.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from robot.motion import ramp

Array = npt.NDArray[np.float64]
METHODS = ("min_jerk", "smooth")  # a keyframe file's choices


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


def _second_derivatives(times: Array, values: Array) -> Array:
    """The spline's second derivatives at the samples (k, j), not-a-knot ends: the third
    derivative is continuous at the second and the last-but-one sample. A tridiagonal
    system in the k - 2 inner unknowns (the ends eliminated), solved by the Thomas
    algorithm for every joint at once."""
    h = np.diff(times)
    d = np.diff(values, axis=0) / h[:, None]
    rhs = 6.0 * (d[1:] - d[:-1])                           # (k - 2, j)
    n = len(rhs)
    sub, diag, sup = h[:-1].copy(), 2.0 * (h[:-1] + h[1:]), h[1:].copy()
    # M0 = ((h0 + h1) M1 - h0 M2) / h1, and the mirror image at the other end.
    h0, h1, hl, hm = h[0], h[1], h[-1], h[-2]
    diag[0] += h0 * (h0 + h1) / h1
    sup[0] -= h0 * h0 / h1
    diag[-1] += hl * (hl + hm) / hm
    sub[-1] -= hl * hl / hm
    c, r = np.empty(n), np.empty_like(rhs)
    c[0], r[0] = sup[0] / diag[0], rhs[0] / diag[0]
    for i in range(1, n):
        w = diag[i] - sub[i] * c[i - 1]
        c[i] = sup[i] / w if i < n - 1 else 0.0
        r[i] = (rhs[i] - sub[i] * r[i - 1]) / w
    inner = np.empty_like(rhs)
    inner[-1] = r[-1]
    for i in range(n - 2, -1, -1):
        inner[i] = r[i] - c[i] * inner[i + 1]
    m = np.empty_like(values)
    m[1:-1] = inner
    m[0] = ((h0 + h1) * inner[0] - h0 * inner[1]) / h1
    m[-1] = ((hl + hm) * inner[-1] - hl * inner[-2]) / hm
    return m


def spline(times: Array, values: Array, t: Array, *, lo: Array | None = None,
           hi: Array | None = None) -> Array:
    """values: (k, j) samples; t: (n,) → (n, j); ``lo`` / ``hi`` (j,): limits [rad] the
    curve stays inside where both samples of its segment do."""
    times, values, t = np.asarray(times, float), np.asarray(values, float), np.asarray(t, float)
    if len(times) < 4:
        return smooth(times, values, t)
    m = _second_derivatives(times, values)
    i, t0, h = _segment(times, t)
    hh = h[:, None]
    a = np.clip((t - t0) / h, 0.0, 1.0)[:, None]           # share of the segment gone
    b = 1.0 - a
    out = (b * values[i] + a * values[i + 1]
           + hh * hh / 6.0 * ((b ** 3 - b) * m[i] + (a ** 3 - a) * m[i + 1]))
    if lo is not None and hi is not None:
        floor = np.minimum(np.minimum(values[i], values[i + 1]), lo)
        ceiling = np.maximum(np.maximum(values[i], values[i + 1]), hi)
        out = np.clip(out, floor, ceiling)
    return np.asarray(out, dtype=np.float64)


def interpolate(method: str, times: Array, values: Array, t: Array) -> Array:
    return (min_jerk if method == "min_jerk" else smooth)(times, values, t)
