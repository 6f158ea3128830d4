"""Math that works on Python floats (fast, one tick) and numpy arrays (vectorised curves).

Kinematics is written once against these functions. A float argument takes the ``math``
path (no numpy call overhead); anything else takes numpy.
Rotations are 9-tuples in row-major order: (r00, r01, r02, r10, ..., r22).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

Num = Any  # float or numpy array
Rot = tuple[Num, Num, Num, Num, Num, Num, Num, Num, Num]
Vec = tuple[Num, Num, Num]

IDENTITY: Rot = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)

_PLAIN_TYPES = frozenset({float, int})


def plain(values: tuple[Num, ...]) -> bool:
    """Every value a Python float or int (not a numpy scalar or array, nor a bool): the
    values for which the ``math`` path gives the bits the general one gives."""
    return _PLAIN_TYPES.issuperset(map(type, values))


def smoothstep(x: float) -> float:
    """3x^2 - 2x^3 of x clipped to [0, 1]."""
    x = min(max(x, 0.0), 1.0)
    return x * x * (3.0 - 2.0 * x)


def sin(x: Num) -> Num:
    return math.sin(x) if type(x) is float else np.sin(x)


def cos(x: Num) -> Num:
    return math.cos(x) if type(x) is float else np.cos(x)


def sqrt(x: Num) -> Num:
    return math.sqrt(x) if type(x) is float else np.sqrt(x)


def atan2(y: Num, x: Num) -> Num:
    if type(y) is float and type(x) is float:
        return math.atan2(y, x)
    return np.arctan2(y, x)


def clip(x: Num, lo: float, hi: float) -> Num:
    if type(x) is float:
        return lo if x < lo else hi if x > hi else x
    return np.clip(x, lo, hi)


def acos(x: Num) -> Num:
    """arccos of ``x`` clipped to [-1, 1] (never NaN)."""
    return math.acos(clip(x, -1.0, 1.0)) if type(x) is float else np.arccos(np.clip(x, -1, 1))


def asin(x: Num) -> Num:
    """arcsin of ``x`` clipped to [-1, 1] (never NaN)."""
    return math.asin(clip(x, -1.0, 1.0)) if type(x) is float else np.arcsin(np.clip(x, -1, 1))


def maximum(x: Num, y: float) -> Num:
    if type(x) is float:
        return x if x > y else y
    return np.maximum(x, y)


def sign(x: Num) -> Num:
    """+1 for x >= 0, else -1."""
    if type(x) is float:
        return 1.0 if x >= 0 else -1.0
    return np.where(x >= 0, 1.0, -1.0)


def rot_x(a: Num) -> Rot:
    c, s = cos(a), sin(a)
    return (1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)


def rot_y(a: Num) -> Rot:
    c, s = cos(a), sin(a)
    return (c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)


def rot_z(a: Num) -> Rot:
    c, s = cos(a), sin(a)
    return (c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)


def matmul(a: Rot, b: Rot) -> Rot:
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a
    b0, b1, b2, b3, b4, b5, b6, b7, b8 = b
    return (
        a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7, a0 * b2 + a1 * b5 + a2 * b8,
        a3 * b0 + a4 * b3 + a5 * b6, a3 * b1 + a4 * b4 + a5 * b7, a3 * b2 + a4 * b5 + a5 * b8,
        a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7, a6 * b2 + a7 * b5 + a8 * b8,
    )


def transpose(a: Rot) -> Rot:
    return (a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8])


def apply(r: Rot, v: Vec) -> Vec:
    """r @ v."""
    x, y, z = v
    return (r[0] * x + r[1] * y + r[2] * z, r[3] * x + r[4] * y + r[5] * z,
            r[6] * x + r[7] * y + r[8] * z)


def apply_t(r: Rot, v: Vec) -> Vec:
    """r.T @ v."""
    x, y, z = v
    return (r[0] * x + r[3] * y + r[6] * z, r[1] * x + r[4] * y + r[7] * z,
            r[2] * x + r[5] * y + r[8] * z)


def post_rx(r: Rot, a: Num) -> Rot:
    """r @ rot_x(a), computing only the columns that change."""
    c, s = cos(a), sin(a)
    return (r[0], c * r[1] + s * r[2], c * r[2] - s * r[1],
            r[3], c * r[4] + s * r[5], c * r[5] - s * r[4],
            r[6], c * r[7] + s * r[8], c * r[8] - s * r[7])


def post_ry(r: Rot, a: Num) -> Rot:
    """r @ rot_y(a)."""
    c, s = cos(a), sin(a)
    return (c * r[0] - s * r[2], r[1], s * r[0] + c * r[2],
            c * r[3] - s * r[5], r[4], s * r[3] + c * r[5],
            c * r[6] - s * r[8], r[7], s * r[6] + c * r[8])


def cos_sin(a: Num) -> tuple[Num, Num]:
    """(cos a, sin a). An array of zeros (a yaw or pitch that a parameter turns off) is
    not evaluated: cos(+-0) = 1 and sin(+-0) = +-0 exactly."""
    if type(a) is not float and isinstance(a, np.ndarray) and not a.any():
        return np.ones_like(a), a
    return cos(a), sin(a)


def rz_ry(yaw: Num, pitch: Num) -> Rot:
    """rot_z(yaw) @ rot_y(pitch)."""
    (cz, sz), (cy, sy) = cos_sin(yaw), cos_sin(pitch)
    return (cz * cy, -sz, cz * sy, sz * cy, cz, sz * sy, -sy, 0.0, cy)
