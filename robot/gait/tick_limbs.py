"""The leg and arm IK of robot.gait.ik on Python floats for the fused tick
(robot.gait.tick): the same operations in the same order, so the same bits, with what
depends on the robot alone precomputed (``leg_constants``, ``arm_constants``)."""

from __future__ import annotations

from math import atan2, cos, sin, sqrt
from typing import NamedTuple

from robot.body.legs import LegChain
from robot.gait.ik import REACH_TOL, Reach
from robot.gait.xmath import Rot


class Leg(NamedTuple):
    """Per-leg constants of ``ik.leg_ik`` [m, m^2]."""

    hx: float
    hy: float
    hz: float
    a: float       # thigh
    b: float       # shin
    ah: float      # ankle height
    far: float     # a + b
    near: float    # |a - b|
    span: float    # 4 a b
    lo: float      # c_lo - REACH_TOL
    hi: float      # c_hi + REACH_TOL
    c_lo: float    # the hip to ankle distances the knee limits allow (ik.leg_reach)
    c_hi: float


class Arm(NamedTuple):
    """Per-arm constants of ``ik.arm_ik`` for the fixed lateral hand offset ``py`` [m]."""

    py: float
    py2: float     # py * py
    lo: float      # the distances the elbow limits allow (ik.arm_reach)
    hi: float
    far: float     # u + f
    near: float    # |u - f|
    far_s: float   # (far - |py|) (far + |py|) of ik.spans
    s_near: float  # (|py| - near) (|py| + near) of ik.spans
    span: float    # 4 u f
    two_u: float   # 2 u
    f_u: float     # f - u
    lo_tol: float  # lo - REACH_TOL
    hi_tol: float  # hi + REACH_TOL


def leg_constants(leg: LegChain, span: Reach) -> Leg:
    """``Leg`` for a simple chain (robot.body.legs.LegChain.simple) within ``span``."""
    a, b = leg.thigh, leg.shin
    hx, hy, hz = leg.hip
    return Leg(hx, hy, hz, a, b, leg.ankle_height, a + b, abs(a - b), 4.0 * a * b,
               span.lo - REACH_TOL, span.hi + REACH_TOL, span.lo, span.hi)


def arm_constants(u: float, f: float, py: float, span: Reach) -> Arm:
    """``Arm`` for upper arm ``u``, forearm ``f`` [m] and the hand's lateral offset ``py``."""
    far, near, s = u + f, abs(u - f), abs(py)
    return Arm(py, py * py, span.lo, span.hi, far, near, (far - s) * (far + s),
               (s - near) * (s + near), 4.0 * u * f, 2.0 * u, f - u,
               span.lo - REACH_TOL, span.hi + REACH_TOL)


def leg_ik(k: Leg, sole: tuple[float, float, float], f: Rot) -> tuple[list[float], bool]:
    """ik.leg_ik on floats: the six leg angles [rad] and the reachable flag."""
    hx, hy, hz, a, b, ah, far, near, span, lo, hi, c_lo, c_hi = k
    f0, f1, f2, f3, f4, f5, f6, f7, f8 = f
    x = hx - (sole[0] + f2 * ah)   # ankle → hip
    y = hy - (sole[1] + f5 * ah)
    z = hz - (sole[2] + f8 * ah)
    rx = f0 * x + f3 * y + f6 * z    # in the foot frame
    ry = f1 * x + f4 * y + f7 * z
    rz = f2 * x + f5 * y + f8 * z
    c = sqrt(rx * rx + ry * ry + rz * rz)
    reachable = (c >= lo) & (c <= hi)
    c = c_lo if c < c_lo else c_hi if c > c_hi else c
    s = abs(c)                       # ik.spans and ik.bend with t = 0
    out = (far - s) * (far + s) - 0.0
    out = 0.0 if out < 0.0 else span if out > span else out
    inn = (s - near) * (s + near) + 0.0
    inn = 0.0 if inn < 0.0 else span if inn > span else inn
    knee = 2.0 * atan2(sqrt(out), sqrt(inn))
    ankle_a = atan2(a * sin(knee), b + a * cos(knee))
    sz_ = 1.0 if rz >= 0 else -1.0
    ankle_roll = atan2(ry * sz_, rz * sz_)
    ankle_pitch = -atan2(rx, sz_ * sqrt(ry * ry + rz * rz)) - ankle_a
    ankle_pitch = atan2(sin(ankle_pitch), cos(ankle_pitch))
    # r = post_ry(post_rx(f, -ankle_roll), -(ankle_pitch + knee)): the entries the hip needs
    cr, sr = cos(-ankle_roll), sin(-ankle_roll)
    r1, r4, r7 = cr * f1 + sr * f2, cr * f4 + sr * f5, cr * f7 + sr * f8
    r8 = cr * f8 - sr * f7
    t = -(ankle_pitch + knee)
    cp, sp = cos(t), sin(t)
    r6, r8 = cp * f6 - sp * r8, sp * f6 + cp * r8
    hip_yaw = atan2(-r1, r4)
    cz, sz = cos(hip_yaw), sin(hip_yaw)
    hip_roll = atan2(r7, -r1 * sz + r4 * cz)
    hip_pitch = atan2(-r6, r8)
    return [hip_yaw, hip_roll, hip_pitch, knee, ankle_pitch, ankle_roll], reachable


def arm_ik(k: Arm, px: float, pz: float) -> tuple[list[float], bool]:
    """ik.arm_ik on floats for the hand at (px, k.py, pz) [m]: three arm angles [rad] and
    the reachable flag."""
    py, py2, lo, hi, far, near, far_s, s_near, span, two_u, f_u, lo_tol, hi_tol = k
    rho2 = px * px + pz * pz
    d = sqrt(rho2 + py2)
    dc = lo if d < lo else hi if d > hi else d
    kk = dc / (d if d > 1e-300 else 1e-300)
    y = py * kk
    y = -dc if y < -dc else dc if y > dc else y
    t = sqrt(rho2)                   # ik.spans(u, f, py * kk, t * kk)
    if kk == 1.0:                    # inside the reach: py's terms precomputed
        t2 = t * t
        out = far_s - t2
        inn = s_near + t2
    else:
        sk, tk = abs(py * kk), t * kk
        t2 = tk * tk
        out = (far - sk) * (far + sk) - t2
        inn = (sk - near) * (sk + near) + t2
    out = 0.0 if out < 0.0 else span if out > span else out
    inn = 0.0 if inn < 0.0 else span if inn > span else inn
    elbow = -2.0 * atan2(sqrt(out), sqrt(inn))
    vx = sqrt(out * inn) / two_u
    vz = f_u - inn / two_u
    ay, az, rr, zz = abs(y), abs(vz), rho2 * kk * kk, vz * vz
    m = rr + zz
    lat2 = (zz * (rr - vx * vx) + rr * (az - ay) * (az + ay)) / (m if m > 1e-300 else 1e-300)
    sign_y = 1.0 if y >= 0 else -1.0
    sign_vz = 1.0 if vz >= 0 else -1.0
    roll = atan2(-sign_y * sign_vz * 0.5 * (ay + az - abs(ay - az)), sqrt(abs(lat2)))
    w = cos(roll) * vz
    pitch = atan2(px * w - pz * vx, pz * w + px * vx + 0.0)
    reachable = (d >= lo_tol) & (d <= hi_tol) & (ay <= az + REACH_TOL)
    return [pitch, roll, elbow], reachable
