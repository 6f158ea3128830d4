"""Rotation matrices for the animation import: about one axis, composed in an Euler order,
decomposed back onto three axes, and from glTF quaternions. Vectorised over frames.

An Euler order names three distinct axes "abc" and means R = R_a(alpha) R_b(beta)
R_c(gamma) (intrinsic, left to right): the BVH channel order, and the order the robot
composes a joint's axes in (hip "zxy": yaw, roll, pitch; robot/previs/bvh.py).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]
AXES = "xyz"


def axis_matrix(axis: str, angle: npt.ArrayLike) -> Array:
    """Rotations (n, 3, 3) by ``angle`` [rad] (n,) about ``axis`` ("x", "y" or "z")."""
    a = np.atleast_1d(np.asarray(angle, dtype=float))
    c, s = np.cos(a), np.sin(a)
    i = AXES.index(axis)
    j, k = (i + 1) % 3, (i + 2) % 3
    out = np.zeros((len(a), 3, 3))
    out[:, i, i] = 1.0
    out[:, j, j] = c
    out[:, k, k] = c
    out[:, j, k] = -s
    out[:, k, j] = s
    return out


def compose(order: str, angles: Array) -> Array:
    """R = R_a R_b R_c for ``order`` "abc"; ``angles`` (n, 3) [rad] → (n, 3, 3)."""
    out = axis_matrix(order[0], angles[:, 0])
    for col in (1, 2):
        out = out @ axis_matrix(order[col], angles[:, col])
    return out


def decompose(order: str, r: Array) -> Array:
    """The angles (n, 3) [rad] with ``compose(order, angles) == r`` for rotations ``r``
    (n, 3, 3); the middle angle in [-pi/2, pi/2] (Tait-Bryan: three distinct axes)."""
    i, j, k = (AXES.index(c) for c in order)
    if len({i, j, k}) != 3:
        raise ValueError(f"Euler order {order!r}: expected three distinct axes of xyz")
    e = 1.0 if (j - i) % 3 == 1 else -1.0     # even permutation of xyz: +1
    beta = np.arcsin(np.clip(e * r[:, i, k], -1.0, 1.0))
    alpha = np.arctan2(-e * r[:, j, k], r[:, k, k])
    gamma = np.arctan2(-e * r[:, i, j], r[:, i, i])
    return np.column_stack([alpha, beta, gamma])


def other_solution(angles: Array) -> Array:
    """The second Tait-Bryan solution of the same rotations: (a + pi, pi - b, c + pi),
    each wrapped to (-pi, pi] (the middle angle beyond +-pi/2)."""
    alt = angles + np.array([np.pi, 0.0, np.pi])
    alt[:, 1] = np.pi - angles[:, 1]
    return (alt + np.pi) % (2 * np.pi) - np.pi


def quat_matrix(q: npt.ArrayLike) -> Array:
    """Unit quaternions (n, 4) as glTF stores them, (x, y, z, w), → rotations (n, 3, 3)."""
    x, y, z, w = (np.asarray(q, dtype=float) / np.linalg.norm(q, axis=-1, keepdims=True)).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], axis=1)
