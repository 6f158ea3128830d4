"""robot.gait.ik_chain.chain_leg_ik on Python floats for the fused tick (robot.gait.tick):
the same operations in the same order (the same bits: tests/test_tick_kernel.py), on the
constants ``chain_constants`` derives once per robot, with no per-call type tests.

``leg_solver`` picks the closed form a leg needs: robot.gait.tick_limbs.leg_ik for a
``simple`` chain (the box model's), ``chain_ik`` for any other.
"""

from __future__ import annotations

from collections.abc import Callable
from math import asin, atan2, cos, sin, sqrt
from typing import Any

from robot.body.legs import LegChain
from robot.gait.ik import Reach
from robot.gait.ik_chain import MAX_STEP, Chain, chain_constants
from robot.gait.tick_limbs import leg_constants, leg_ik
from robot.gait.xmath import Rot

Sole = tuple[float, float, float]
#: A leg's float IK and its constants: ``fn(k, sole, foot_rot) -> (angles, reachable)``.
Solver = tuple[Callable[[Any, Sole, Rot], tuple[list[float], bool]], Any]


def leg_solver(leg: LegChain, span: Reach) -> Solver:
    """The float IK of ``leg`` within the knee's ``span`` and its constants."""
    if leg.simple:
        return leg_ik, leg_constants(leg, span)
    return chain_ik, chain_constants(leg, span)


def chain_ik(k: Chain, sole: Sole, f: Rot) -> tuple[list[float], bool]:
    """chain_leg_ik on floats: the six leg angles [rad] and the reachable flag."""
    (six, yaw_roll, px, py, pz, ux, uy, hx, hy, hz, drop, ad, ox, oy, oz, k0, k1, a, b,
     far, near, span, lo, hi, lo_tol, hi_tol, steps, kb) = k
    f0, f1, f2, f3, f4, f5, f6, f7, f8 = f
    sx, sy, sz = sole
    if six:
        qx = sx - (f0 * ox + f1 * oy + f2 * oz)
        qy = sy - (f3 * ox + f4 * oy + f5 * oz)
        qz = sz - (f6 * ox + f7 * oy + f8 * oz)
    else:
        qx, qy, qz = sx, sy, sz
    wx, wy, wz = qx - px, qy - py, qz - pz
    ry = f1 * wx + f4 * wy + f7 * wz
    rz = f2 * wx + f5 * wy + f8 * wz
    sg = 1.0 if rz >= 0 else -1.0
    rho = sqrt(ry * ry + rz * rz)
    x = sg * (k0 + k1) / (rho if rho > 1e-300 else 1e-300)
    side_ok = abs(x) <= 1.0
    roll = atan2(ry * sg, rz * sg) - asin(-1.0 if x < -1.0 else 1.0 if x > 1.0 else x)
    if k1 != 0.0:
        gc, gs = (f7, f8) if yaw_roll else (f1, f2)
        for _ in range(steps):
            c, s = cos(roll), sin(roll)
            nc = gc * c - gs * s
            root = 1.0 - nc * nc
            root = sqrt(root if root > 1e-24 else 1e-24)
            g = c * ry - s * rz - k0 - k1 * root
            dg = -s * ry - c * rz - k1 * nc * (gc * s + gs * c) / root
            step = g / (dg + (1.0 if dg >= 0 else -1.0) * 1e-300)
            roll = roll - (-MAX_STEP if step < -MAX_STEP else MAX_STEP if step > MAX_STEP
                           else step)
        side_ok = abs(k0 + k1 * root) <= rho
    c6, s6 = cos(roll), sin(roll)
    n0, n1, n2 = c6 * f1 - s6 * f2, c6 * f4 - s6 * f5, c6 * f7 - s6 * f8
    e0, e1, e2 = c6 * f2 + s6 * f1, c6 * f5 + s6 * f4, c6 * f8 + s6 * f7
    if yaw_roll:
        yaw = atan2(-n0, n1)
        hip_roll = atan2(n2, sqrt(n0 * n0 + n1 * n1))
    else:
        yaw = atan2(-n0, sqrt(n1 * n1 + n2 * n2))
        hip_roll = atan2(n2, n1)
    cy, sy_ = cos(yaw), sin(yaw)
    cr, sr = cos(hip_roll), sin(hip_roll)
    if yaw_roll:
        hpx = px + (cy * ux - sy_ * uy) - drop * (sy_ * sr)
        hpy = py + (sy_ * ux + cy * uy) + drop * (cy * sr)
        hpz = hz - drop * cr
    else:
        v = sy_ * ux + cy * uy
        hpx = px + (cy * ux - sy_ * uy)
        hpy = hy + cr * (v - uy) + sr * drop
        hpz = hz + sr * (v - uy) - cr * drop
    if six:
        ax, ay, az = qx + ad * e0, qy + ad * e1, qz + ad * e2
    else:
        ax = sx - (f0 * ox + n0 * oy + e0 * oz)
        ay = sy - (f3 * ox + n1 * oy + e1 * oz)
        az = sz - (f6 * ox + n2 * oy + e2 * oz)
    vx, vy, vz = hpx - ax, hpy - ay, hpz - az
    px_ = f0 * vx + f3 * vy + f6 * vz
    pz_ = e0 * vx + e1 * vy + e2 * vz
    dist = sqrt(px_ * px_ + pz_ * pz_)
    reachable = side_ok & (dist >= lo_tol) & (dist <= hi_tol)
    s_ = lo if dist < lo else hi if dist > hi else dist
    out = (far - s_) * (far + s_)
    out = 0.0 if out < 0.0 else span if out > span else out
    inn = (s_ - near) * (s_ + near)
    inn = 0.0 if inn < 0.0 else span if inn > span else inn
    knee = kb * (2.0 * atan2(sqrt(out), sqrt(inn)))
    ankle_a = atan2(a * sin(knee), b + a * cos(knee))
    ankle_pitch = -atan2(px_, pz_) - ankle_a
    ankle_pitch = atan2(sin(ankle_pitch), cos(ankle_pitch))
    t = -(ankle_pitch + knee)
    ct, st = cos(t), sin(t)
    if yaw_roll:
        hip_pitch = atan2(-(ct * f6 - st * e2), st * f6 + ct * e2)
    else:
        hip_pitch = atan2(st * f0 + ct * e0, ct * f0 - st * e0)
    return [yaw, hip_roll, hip_pitch, knee, ankle_pitch, roll if six else roll - roll], reachable
