"""N-step capturability of the linear inverted pendulum with a finite foot: the largest
push a perfect controller could still stop from with 0, 1 or 2 steps (Koolen, de Boer,
Rebula, Goswami and Pratt, "Capturability-based analysis and control of legged
locomotion, Part 1: Theory and application to three simple gait models", IJRR 31(9),
2012; the model of its section on the 3D-LIPM with finite-sized foot).

What is used from the paper, per horizontal axis (SI units: m, s, 1/s):

- the pendulum: c'' = omega0^2 (c - p), omega0 = sqrt(g / z0), for a centre of mass c at
  the constant height z0 over the ground and the centre of pressure p inside the base of
  support;
- the instantaneous capture point r = c + c' / omega0 and its dynamics r' = omega0 (r - p):
  for p held constant over a time t, r(t) = p + (r(0) - p) e^(omega0 t);
- 0-step capturable: r inside the base of support (the pendulum stops over p = r);
- N-step capture regions built backward from the last foot: a state is N-step capturable
  if, after the minimum step time with p anywhere in the base of support, a step within
  the maximum step length reaches an (N-1)-step capturable state. For a round foot of
  radius r_max and a round reach of l_max the paper's regions are discs of radius
  d_N = (d_(N-1) - r_max + l_max) e^(-omega0 dt_s) + r_max, d_0 = r_max.

Generalised here to a rectangular sole and a reach that differs forward, backward,
outward and inward (a foot cannot cross the other): the pendulum's two axes are
independent and every set is then an interval per axis, so the recursion is interval
arithmetic. Over a step of time t from a foot whose centre of pressure may be anywhere in
P, with the landing ankle anywhere in A (relative to the standing ankle) and the region
Q already capturable from the new ankle, r(t) = e^(w t) r0 - (e^(w t) - 1) p with p in
P (a constant p reaches every point a varying one does: the weights sum to e^(w t) - 1),
so the region now is e^(-w t) ((e^(w t) - 1) P + A + Q), sums of intervals. With
P = [-r, r], A = [-l, l] and Q = [-d, d] that is the disc recursion above to the digit
(tests/test_capturability.py). The push limit along a direction u is then where the ray
r0 + J u / (M omega0) leaves the region (the push's impulse J changes the centre of mass's
velocity by J / M).

Pure functions of floats and numpy arrays.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

GRAVITY = 9.81  # [m/s^2]


Num = float | npt.NDArray[np.float64]


class Interval(NamedTuple):
    """[lo, hi] on one axis [m]: floats, or arrays of one shape (one interval per
    element: a grid of step times)."""

    lo: Num
    hi: Num

    def __add__(self, other: object) -> Interval:     # Minkowski sum
        if not isinstance(other, Interval):
            return NotImplemented
        return Interval(self.lo + other.lo, self.hi + other.hi)

    def scaled(self, k: Num) -> Interval:
        """k x the interval, k >= 0."""
        return Interval(k * self.lo, k * self.hi)

    def shifted(self, d: Num) -> Interval:
        return Interval(self.lo + d, self.hi + d)


class Box(NamedTuple):
    """An axis-aligned region: forward (x) and left (y) intervals [m]."""

    x: Interval
    y: Interval


class Step(NamedTuple):
    """One step of a capture: ``support``, the standing foot's centre-of-pressure region
    relative to its ankle; ``reach``, where the swinging foot's ankle may land relative to
    the standing ankle; ``t``: the swing's time [s] (>= 0)."""

    support: Box
    reach: Box
    t: Num


def omega0(height: float) -> float:
    """The pendulum's natural frequency sqrt(g / z0) [1/s] for a centre of mass
    ``height`` [m] over the ground."""
    if not height > 0.0:
        raise ValueError(f"the centre of mass must be above the ground, got {height} m")
    return math.sqrt(GRAVITY / height)


def capture_point_after(r0: float, p: float, w0: float, t: float) -> float:
    """The capture point [m] after ``t`` [s] with the centre of pressure held at ``p``:
    p + (r0 - p) e^(w0 t)."""
    return p + (r0 - p) * math.exp(w0 * t)


def _region(support: Interval, reach: Interval, after: Interval, w0: float, t: Num
            ) -> Interval:
    grow = np.exp(w0 * np.asarray(t, dtype=float))
    return (support.scaled(grow - 1.0) + reach + after).scaled(1.0 / grow)


def region(steps: Sequence[Step], last: Box, w0: float) -> Box:
    """The capture points (relative to the first standing ankle) from which ``steps``
    (in order) end with the capture point in ``last``, the last foot's region relative to
    its ankle; no steps: ``last`` itself (0-step)."""
    qx, qy = last.x, last.y
    for s in reversed(steps):
        qx = _region(s.support.x, s.reach.x, qx, w0, s.t)
        qy = _region(s.support.y, s.reach.y, qy, w0, s.t)
    return Box(qx, qy)


def disc_radius(n: int, r_max: float, l_max: float, w0: float, dt_s: float) -> float:
    """The paper's N-step capture radius for a round foot and reach:
    d_N = (d_(N-1) - r_max + l_max) e^(-w0 dt_s) + r_max, d_0 = r_max [m]."""
    d = r_max
    for _ in range(n):
        d = (d - r_max + l_max) * math.exp(-w0 * dt_s) + r_max
    return d


def ray_exit(start: tuple[float, float], u: tuple[float, float], box: Box) -> Num:
    """The largest s >= 0 with start + s u inside ``box`` (of floats or arrays: then one
    s per element); 0 where ``start`` is outside it (no push is then survivable with that
    region) [units of s: m per unit of u]."""
    hi: Num = np.inf
    inside: npt.NDArray[np.bool_] = np.array(True)
    for p, d, iv in ((start[0], u[0], box.x), (start[1], u[1], box.y)):
        lo_, hi_ = np.asarray(iv.lo, dtype=float), np.asarray(iv.hi, dtype=float)
        inside = inside & (lo_ - 1e-12 <= p) & (p <= hi_ + 1e-12)
        if d > 0.0:
            hi = np.minimum(hi, (hi_ - p) / d)
        elif d < 0.0:
            hi = np.minimum(hi, (lo_ - p) / d)
    out = np.where(inside, np.maximum(hi, 0.0), 0.0)
    return float(out) if np.ndim(out) == 0 else out


def polygon_exit(start: tuple[float, float], u: tuple[float, float],
                 polygon: npt.NDArray[np.float64]) -> float:
    """The largest s >= 0 with start + s u inside the convex ``polygon`` (n, 2; either
    winding); 0 when ``start`` is outside it."""
    pts = np.asarray(polygon, dtype=float)
    centre = pts.mean(axis=0)
    hi = math.inf
    n = len(pts)
    for i in range(n):
        a, b = pts[i], pts[(i + 1) % n]
        normal = np.array([b[1] - a[1], a[0] - b[0]])
        if float(np.dot(normal, centre - a)) > 0.0:      # outward: away from the centre
            normal = -normal
        gap = float(np.dot(normal, a - np.asarray(start)))   # >= 0 inside
        if gap < -1e-12 * max(1.0, float(np.linalg.norm(normal))):
            return 0.0
        rate = float(np.dot(normal, u))
        if rate > 0.0:
            hi = min(hi, gap / rate)
    return max(hi, 0.0) if math.isfinite(hi) else math.inf


def hull(points: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """The convex hull (counter-clockwise, monotone chain) of 2-D points (n, 2)."""
    pts = sorted({(float(x), float(y)) for x, y in np.asarray(points, dtype=float)})
    if len(pts) < 3:
        return np.array(pts)

    def cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]
              ) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    lower: list[tuple[float, float]] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list[tuple[float, float]] = []
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])
