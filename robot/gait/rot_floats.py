"""3x3 rotations on Python floats for the fused tick (robot.gait.tick): the operations of
robot.gait.xmath written out for floats, so the tick gives the same bits as the general
functions. Rotations are row-major 9-tuples."""

from __future__ import annotations

from math import cos, sin

from robot.gait.xmath import Rot, post_rx


def rz_ry(yaw: float, pitch: float) -> Rot:
    """xmath.rz_ry on floats (a zero angle is common: cos(+-0) = 1, sin(+-0) = +-0)."""
    cz, sz = (1.0, yaw) if yaw == 0.0 else (cos(yaw), sin(yaw))
    cy, sy = (1.0, pitch) if pitch == 0.0 else (cos(pitch), sin(pitch))
    return (cz * cy, -sz, cz * sy, sz * cy, cz, sz * sy, -sy, 0.0, cy)


def per_foot(pelvis: Rot, yaw: float, pitch: float, roll: float, foot_roll: float,
              foot_pitch: float) -> Rot:
    """targets._per_foot on floats."""
    if foot_roll == 0.0 and foot_pitch == 0.0:
        return pelvis
    return post_rx(rz_ry(yaw, pitch + foot_pitch), roll + foot_roll)


def apply_t(r: Rot, x: float, y: float, z: float) -> tuple[float, float, float]:
    """xmath.apply_t: r.T @ (x, y, z)."""
    return (r[0] * x + r[3] * y + r[6] * z, r[1] * x + r[4] * y + r[7] * z,
            r[2] * x + r[5] * y + r[8] * z)


def t_matmul(a: Rot, b: Rot) -> Rot:
    """xmath.matmul(xmath.transpose(a), b)."""
    a0, a3, a6, a1, a4, a7, a2, a5, a8 = a
    b0, b1, b2, b3, b4, b5, b6, b7, b8 = b
    return (
        a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7, a0 * b2 + a1 * b5 + a2 * b8,
        a3 * b0 + a4 * b3 + a5 * b6, a3 * b1 + a4 * b4 + a5 * b7, a3 * b2 + a4 * b5 + a5 * b8,
        a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7, a6 * b2 + a7 * b5 + a8 * b8,
    )
