"""What lies between the frames of a sampled curve that is smooth but for kinks: a C2
spline on each smooth piece, the pieces meeting at the kinks the frames imply.

A gait's joint curves are smooth but for kinks: the swing foot's lift starts and ends
with a step in velocity (robot/gait/expressions.py), and a kink between two frames is
rounded off by any smooth interpolant (the not-a-knot spline rings 0.02 rad around the
knee's at 30 fps). So a kink is found and put back, the idea of Harten's subcell
resolution (J. Comput. Phys. 83, 1989):

1. screen: the fourth difference of frames on one cubic is 0, so ``d4[j]`` over frames
   j..j+4 measures how far five frames are from one smooth curve. A kink in the segment
   (i, i + 1) spoils the four windows that hold both frames; the windows just outside
   them stay clean. A segment whose spoiled windows are ``RATIO`` times worse than the
   clean ones is a candidate.
2. test: on the frames around a candidate (``SIDE`` each side), a cubic plus a kink
   ``dv (t - tau)+`` at the best ``tau`` in the segment is fitted by least squares; it is
   a kink when its squared residual is ``FIT_RATIO`` times the cubic's alone. It is placed
   where the cubic through the four frames before it meets the one through the four after
   (each with its own curvature); of two candidates side by side (a kink near a frame
   screens in both), the one whose pieces meet inside it, then the better fit.
3. join: each smooth piece (its frames, and the kink points at its ends: the fitted
   curve's value at ``tau``) gets its own not-a-knot spline (robot.motion.interp.spline).

Frames must be evenly spaced (a BVH's, a glTF's resampled tracks).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from robot.motion.interp import smooth, spline

Array = npt.NDArray[np.float64]

#: How much worse a segment's spoiled windows must be than its clean ones [1].
RATIO = 8.0
#: How much smaller the kink's squared residual than the cubic's [1] (a kink on a smooth
#: curve buys about 2; the gait's weakest kink, the hip's, 45).
FIT_RATIO = 10.0
#: Below this the fourth differences are rounding, not shape [rad].
FLOOR = 1e-6
#: Frames each side of a segment in the fit.
SIDE = 5
#: Powers of (t - tau)+ in the fit (1: a step in velocity; 2 and 3 fitted the gait's
#: kinks worse on these ten frames: 0.012 and 0.019 rad against 0.0096 before placing).
KINK_TERMS = 1
#: Kink positions tried per segment, then refined by halving the step this many times.
GRID, REFINE = 21, 12
#: A kink this close to a frame [share of a frame] is at that frame.
SNAP = 0.02


def _candidates(values: Array) -> list[int]:
    d4 = np.abs(np.diff(values, 4))
    pad = np.concatenate([np.zeros(5), d4, np.zeros(5)])    # pad[j + 5] = d4[j]
    i = np.arange(1, len(values) - 2)

    def window(offset: int) -> Array:
        return np.asarray(pad[i + offset + 5], dtype=np.float64)
    spoiled = np.max([window(o) for o in range(-3, 1)], axis=0)
    clean = np.max([window(o) for o in (-5, -4, 1, 2)], axis=0)
    return [int(k) for k in i[spoiled > RATIO * clean + FLOOR]]


def _fit(x: Array, y: Array, s: float | None) -> tuple[float, Array]:
    """Least squares of a cubic (plus a kink at ``s``) in ``x``; (residual, coefficients)."""
    cols = [np.ones_like(x), x, x * x, x * x * x]
    if s is not None:                # the piece after the kink
        after = np.maximum(x - s, 0.0)
        cols += [after ** p for p in range(1, KINK_TERMS + 1)]
    a = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(a, y, rcond=None)
    r = y - a @ coef
    return float(r @ r), np.asarray(coef, dtype=np.float64)


def _kink_in(values: Array, i: int) -> tuple[float, float, float] | None:
    """(rank, tau [frames from i], value) of the best kink in segment ``i``, or None when
    a kink fits no better than the cubic; rank: the fit's squared residual, plus 1 when
    the pieces meet outside the segment (a kink near a frame screens in both segments:
    the one it lies in places it best)."""
    a, b = max(0, i + 1 - SIDE), min(len(values), i + 1 + SIDE)
    if b - a < 6:
        return None
    x = np.arange(a, b, dtype=float) - i
    y = values[a:b]
    smooth_res, _ = _fit(x, y, None)
    grid = np.linspace(0.0, 1.0, GRID)
    res = [(_fit(x, y, float(s))[0], float(s)) for s in grid]
    best, s = min(res)
    step = 1.0 / (GRID - 1)
    for _ in range(REFINE):
        step /= 2
        for c in (s - step, s + step):
            if 0.0 <= c <= 1.0:
                r = _fit(x, y, c)[0]
                if r < best:
                    best, s = r, c
    if not best * FIT_RATIO < smooth_res or smooth_res < len(x) * FLOOR * FLOOR:
        return None
    met = _meeting(values, i)
    if met is not None:
        outside = 0.0 if 0.0 <= met[0] <= 1.0 else 1.0    # ranks first among neighbours
        return outside + best, *met
    _, coef = _fit(x, y, s)
    return best, s, float(coef[0] + coef[1] * s + coef[2] * s * s + coef[3] * s ** 3)


def _meeting(values: Array, i: int) -> tuple[float, float] | None:
    """Where the cubic through the four frames up to ``i`` meets the one through the four
    from ``i + 1`` (each piece with its own curvature: this places a kink closer than the
    fit's single cubic), within a quarter frame of the segment: (tau [frames from i],
    value), or None."""
    a, b = max(0, i - 3), min(len(values), i + 5)
    if i + 1 - a < 2 or b - i - 1 < 2:
        return None
    left = np.poly1d(np.polyfit(np.arange(a, i + 1) - i, values[a:i + 1], min(3, i - a)))
    right = np.poly1d(np.polyfit(np.arange(i + 1, b) - i, values[i + 1:b], min(3, b - i - 2)))
    roots = [float(r.real) for r in np.atleast_1d((left - right).roots)
             if abs(r.imag) < 1e-9 and -0.25 <= r.real <= 1.25]
    if not roots:
        return None
    tau = min(roots, key=lambda r: abs(r - 0.5))
    return tau, float(left(tau))


def kinks(values: Array) -> list[tuple[float, float]]:
    """The kinks of one joint's evenly spaced frames ``values`` (k,) [rad]: (position
    [frames from the first], value [rad]) in order."""
    if len(values) < 6:
        return []
    found: list[tuple[int, float, float, float]] = []
    for i in _candidates(values):
        k = _kink_in(values, i)
        if k is None:
            continue
        if found and found[-1][0] == i - 1:
            if k[0] < found[-1][1]:
                found[-1] = (i, *k)
            continue
        found.append((i, *k))
    return [(i + s, v) for i, _, s, v in found]


def piecewise(times: Array, values: Array, t: Array) -> Array:
    """One joint's frames ``values`` (k,) at evenly spaced ``times`` (k,) [s], evaluated
    at ``t`` (n,): the spline on each smooth piece, the pieces joined at the kinks."""
    h = float(times[1] - times[0])
    points = [(float(f), float(v), False) for f, v in zip(range(len(times)), values, strict=True)]
    for pos, v in kinks(values):
        near = round(pos)
        if abs(pos - near) < SNAP:
            points[near] = (points[near][0], points[near][1], True)   # at a frame
        else:
            points.append((pos, v, True))
    points.sort(key=lambda p: p[0])
    cuts = [n for n, p in enumerate(points) if p[2]]
    if not cuts:
        return spline(times, values[:, None], t)[:, 0]
    pos = np.array([p[0] for p in points]) * h + times[0]
    val = np.array([p[1] for p in points])
    out = np.empty(len(t))
    edges = [0, *cuts, len(points) - 1]
    for n, (lo, hi) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        if hi <= lo:
            continue
        mask = np.ones(len(t), dtype=bool)
        if n > 0:
            mask &= t >= pos[lo]
        if hi < len(points) - 1:
            mask &= t < pos[hi]
        if mask.any():
            ta, va = pos[lo:hi + 1], val[lo:hi + 1, None]
            out[mask] = (spline(ta, va, t[mask]) if len(ta) >= 4
                         else smooth(ta, va, t[mask]))[:, 0]
    return out


def sampled(times: Array, values: Array, t: Array, *, lo: Array, hi: Array) -> Array:
    """values (k, j) frames at evenly spaced ``times`` → (n, j) at ``t``, each joint by
    ``piecewise``, kept inside the limits ``lo`` / ``hi`` (j,) [rad] wherever both frames of
    a segment are (robot.motion.interp.spline)."""
    times, values, t = np.asarray(times, float), np.asarray(values, float), np.asarray(t, float)
    if len(times) < 4:
        return smooth(times, values, t)
    out = np.column_stack([piecewise(times, values[:, c], t) for c in range(values.shape[1])])
    i = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    floor = np.minimum(np.minimum(values[i], values[i + 1]), lo)
    ceiling = np.maximum(np.maximum(values[i], values[i + 1]), hi)
    return np.asarray(np.clip(out, floor, ceiling), dtype=np.float64)
