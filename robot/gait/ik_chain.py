"""Closed-form IK of a real leg (robot.body.legs.LegChain): offset hip axes, sideways
offsets, an ankle roll axis below the pitch axis, a sole point off the ankle, 5-DoF legs.

``chain_leg_ik`` inverts ``robot.body.legs.fk``. A ``simple`` chain (the axes meet as the
box model's) is solved by robot.gait.ik's closed form, bit for bit; any other as follows.

The three pitch axes share one direction n. With ankle roll a (6-DoF), n = F Rx(-a) y
for the target foot rotation F. Every offset but two drops out of n . (A - P), A the ankle
roll point (the sole less F times its offset), P a point of the hip: for order
"yaw_roll" P is the yaw axis at the hip's height and n . (A - P) = d + u_y cos(hip roll);
for "roll_yaw" P is the yaw axis at the roll axis's y and n . (A - P) = d + u_y (1 -
cos(hip yaw)), with d the lateral offset and u = hip - yaw axis (x, y). In the foot frame
r = F^T (A - P) this reads

    cos(a) r_y - sin(a) r_z = k0 + k1 sqrt(1 - (g_c cos(a) - g_s sin(a))^2)

(g: row z of F for yaw_roll, row x for roll_yaw). With k1 = u_y = 0 it is linear in
(cos a, sin a): a = atan2(r_y, r_z) - asin(k0 / |r|), the box model's atan2 when k0 = 0.
Otherwise ``NEWTON`` Newton steps from that with the root term at 1 (the error falls from
~k1 (1 - cos) / |r| to ~1e-14 rad in two while |u_y| < 0.1 (thigh + shin), else in three:
tests/test_ik_chain.py). n then gives the hip yaw and roll, these the hip pitch point,
and the knee, ankle pitch and hip pitch follow as robot.gait.ik.leg_ik's: the law of
cosines in the pitch plane, clamped along the ankle → hip line within the knee limits'
span; a leg whose knee bends backward (``LegChain.knee_back``) takes the other branch of
the law, the knee's angle negated (``Chain.kb``), the rest of the solution unchanged.

A leg without ankle roll keeps the sole point and the foot's x axis (its heading and
pitch) exactly and gives up the roll about that axis: the same equation with A the sole
point, the foot's offset from the ankle pitch axis folded into k0; the achieved foot is
F Rx(-a) and ``LegIK.roll_lost`` = a (the angle between the target's and the achieved
sole normal, signed). Without hip yaw the leg is solved as if it had one there and the
yaw is dropped, as for the box model's 5-DoF legs. Units: m, rad.
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

from robot.body.legs import ORDERS, LegChain
from robot.errors import ConfigError
from robot.gait import xmath as xm
from robot.gait.ik import REACH_TOL, LegIK, Reach, leg_ik_at, reach
from robot.gait.xmath import Rot, Vec

#: Newton steps on the lateral constraint when the yaw axis is off the hip sideways: 2
#: while that offset is under ``NEWTON_NEAR`` of the leg's length (thigh + shin), else 3.
NEWTON = (2, 3)
NEWTON_NEAR = 0.1
#: The largest Newton step [rad]: a guard for targets far out of reach.
MAX_STEP = 0.5


class Chain(NamedTuple):
    """A non-simple leg's constants [m] (``chain_constants``; ``lo``..``hi`` [m] is the
    span the knee limits allow)."""

    six: bool        # has ankle roll
    yaw_roll: bool   # order "yaw_roll" (else "roll_yaw")
    px: float        # P (module docstring)
    py: float
    pz: float
    ux: float        # hip - yaw axis
    uy: float
    hx: float        # hip (roll axis point)
    hy: float
    hz: float
    drop: float      # roll_drop
    ad: float        # ankle_drop
    ox: float        # the sole from the ankle roll point (6-DoF) or pitch point (5-DoF)
    oy: float
    oz: float
    k0: float
    k1: float
    a: float         # thigh
    b: float         # shin
    far: float       # a + b
    near: float      # |a - b|
    span: float      # 4 a b
    lo: float
    hi: float
    lo_tol: float    # lo - REACH_TOL
    hi_tol: float    # hi + REACH_TOL
    steps: int       # Newton steps (NEWTON)
    kb: float        # the knee's bend direction: 1.0 forward, -1.0 backward (knee_back)


def layout_name(leg: LegChain) -> str:
    """The leg's layout in words, e.g. "6-DoF yaw_roll", "5-DoF without ankle roll"."""
    if not leg.has_yaw and not leg.has_ankle_roll:
        return "4-DoF (no hip yaw, no ankle roll)"
    if not leg.has_yaw:
        return "5-DoF without hip yaw"
    dof = "6-DoF" if leg.has_ankle_roll else "5-DoF without ankle roll,"
    return f"{dof} {leg.order}"


def check_layout(leg: LegChain, *, where: str = "leg") -> None:
    """ConfigError unless ``chain_leg_ik`` solves ``leg``: 6-DoF yaw_roll, 5-DoF without
    hip yaw, 5-DoF without ankle roll (yaw_roll or roll_yaw), with any offsets."""
    side = f"{where} {leg.side!r}"
    if leg.side not in ("r", "l"):
        raise ConfigError(f"{where}: side {leg.side!r}; valid: 'r', 'l'")
    if leg.order not in ORDERS:
        raise ConfigError(f"{side}: order {leg.order!r}; valid: {', '.join(ORDERS)}")
    if not leg.thigh > 0.0 or not leg.shin > 0.0:
        raise ConfigError(f"{side}: thigh {leg.thigh:g} m, shin {leg.shin:g} m; the IK "
                          "needs both > 0")
    name = layout_name(leg)
    if not leg.has_yaw and not leg.has_ankle_roll:
        raise ConfigError(f"{side}: layout {name} is not solved: a foot needs 5 leg joints "
                          "(hip yaw or ankle roll)")
    if leg.has_yaw and leg.has_ankle_roll and leg.order == "roll_yaw":
        raise ConfigError(f"{side}: layout {name} (hip roll before hip yaw with ankle roll) "
                          "is not solved; solved: 6-DoF yaw_roll, 5-DoF without hip yaw, "
                          "5-DoF without ankle roll (yaw_roll or roll_yaw)")


def knee_span(leg: LegChain, knee_lo: float, knee_hi: float) -> Reach:
    """The hip to ankle distances [m] ``leg`` spans with its knee between ``knee_lo`` and
    ``knee_hi`` [rad] (the joint's limits): bends of ``knee_lo``..``knee_hi``, or of
    ``-knee_hi``..``-knee_lo`` for a knee that bends backward (``knee_back``)."""
    lo, hi = (-knee_hi, -knee_lo) if leg.knee_back else (knee_lo, knee_hi)
    return reach(leg.thigh, leg.shin, lo, hi)


@lru_cache(maxsize=64)
def chain_constants(leg: LegChain, span: Reach | None = None) -> Chain:
    """What ``chain_leg_ik`` derives from the leg alone (span: as leg_ik's)."""
    hx, hy, hz = leg.hip
    yx, yy = leg.yaw_axis if leg.yaw_axis is not None else (hx, hy)
    ux, uy = hx - yx, hy - yy
    sx, sy, sz = leg.sole
    six, yaw_roll = leg.has_ankle_roll, leg.order == "yaw_roll"
    oz = sz if six else sz - leg.ankle_drop
    k0 = leg.lateral + (0.0 if six else sy)
    px, py, k1 = (yx, yy, uy) if yaw_roll else (yx, hy, -uy)
    if not yaw_roll:
        k0 += uy
    a, b = leg.thigh, leg.shin
    lo, hi = span if span is not None else (abs(a - b), a + b)
    return Chain(six, yaw_roll, px, py, hz, ux, uy, hx, hy, hz, leg.roll_drop,
                 leg.ankle_drop, sx, sy, oz, k0, k1, a, b, a + b, abs(a - b), 4.0 * a * b,
                 lo, hi, lo - REACH_TOL, hi + REACH_TOL,
                 NEWTON[0] if abs(uy) < NEWTON_NEAR * (a + b) else NEWTON[1],
                 -1.0 if leg.knee_back else 1.0)


def chain_leg_ik(leg: LegChain, sole: Vec, foot_rot: Rot = xm.IDENTITY, *,
                 span: Reach | None = None) -> LegIK:
    """Leg angles [rad] (``robot.body.legs.fk``'s order) that put the sole point at
    ``sole`` [m] with foot rotation ``foot_rot`` (pelvis frame), floats or arrays; span:
    the hip to ankle distances the knee's limits allow (robot.gait.ik.leg_reach with the
    leg's thigh and shin; None: the geometry's). Never NaN, never raises; ``reachable``
    False where the target was clamped (see the module docstring)."""
    if leg.simple:
        return leg_ik_at(leg.hip, leg.thigh, leg.shin, leg.ankle_height, sole, foot_rot,
                         span=span)
    k = chain_constants(leg, span)
    f0, f1, f2, f3, f4, f5, f6, f7, f8 = foot_rot
    sx, sy, sz = sole
    if k.six:     # the ankle roll point
        qx = sx - (f0 * k.ox + f1 * k.oy + f2 * k.oz)
        qy = sy - (f3 * k.ox + f4 * k.oy + f5 * k.oz)
        qz = sz - (f6 * k.ox + f7 * k.oy + f8 * k.oz)
    else:
        qx, qy, qz = sx, sy, sz
    wx, wy, wz = qx - k.px, qy - k.py, qz - k.pz
    ry = f1 * wx + f4 * wy + f7 * wz
    rz = f2 * wx + f5 * wy + f8 * wz
    sg = xm.sign(rz)
    rho = xm.sqrt(ry * ry + rz * rz)
    x = sg * (k.k0 + k.k1) / xm.maximum(rho, 1e-300)
    side_ok = abs(x) <= 1.0
    roll = xm.atan2(ry * sg, rz * sg) - xm.asin(x)
    if k.k1 != 0.0:
        gc, gs = (f7, f8) if k.yaw_roll else (f1, f2)
        for _ in range(k.steps):
            c, s = xm.cos(roll), xm.sin(roll)
            nc = gc * c - gs * s
            root = xm.sqrt(xm.maximum(1.0 - nc * nc, 1e-24))
            g = c * ry - s * rz - k.k0 - k.k1 * root
            dg = -s * ry - c * rz - k.k1 * nc * (gc * s + gs * c) / root
            roll = roll - xm.clip(g / (dg + xm.sign(dg) * 1e-300), -MAX_STEP, MAX_STEP)
        side_ok = abs(k.k0 + k.k1 * root) <= rho
    c6, s6 = xm.cos(roll), xm.sin(roll)
    # The foot before its ankle roll, F Rx(-roll): columns (f0, f3, f6), n, e.
    n0, n1, n2 = c6 * f1 - s6 * f2, c6 * f4 - s6 * f5, c6 * f7 - s6 * f8
    e0, e1, e2 = c6 * f2 + s6 * f1, c6 * f5 + s6 * f4, c6 * f8 + s6 * f7
    if k.yaw_roll:
        yaw = xm.atan2(-n0, n1)
        hip_roll = xm.atan2(n2, xm.sqrt(n0 * n0 + n1 * n1))
    else:
        yaw = xm.atan2(-n0, xm.sqrt(n1 * n1 + n2 * n2))
        hip_roll = xm.atan2(n2, n1)
    cy, sy_ = xm.cos(yaw), xm.sin(yaw)
    cr, sr = xm.cos(hip_roll), xm.sin(hip_roll)
    ux, uy, drop = k.ux, k.uy, k.drop
    if k.yaw_roll:  # the hip pitch point: fk's yaw_point + Rz (hip - yaw_point) + R1 drop
        hpx = k.px + (cy * ux - sy_ * uy) - drop * (sy_ * sr)
        hpy = k.py + (sy_ * ux + cy * uy) + drop * (cy * sr)
        hpz = k.hz - drop * cr
    else:
        v = sy_ * ux + cy * uy
        hpx = k.px + (cy * ux - sy_ * uy)
        hpy = k.hy + cr * (v - uy) + sr * drop
        hpz = k.hz + sr * (v - uy) - cr * drop
    if k.six:       # the ankle pitch point
        ax, ay, az = qx + k.ad * e0, qy + k.ad * e1, qz + k.ad * e2
    else:
        ax = sx - (f0 * k.ox + n0 * k.oy + e0 * k.oz)
        ay = sy - (f3 * k.ox + n1 * k.oy + e1 * k.oz)
        az = sz - (f6 * k.ox + n2 * k.oy + e2 * k.oz)
    vx, vy, vz = hpx - ax, hpy - ay, hpz - az     # ankle → hip, in the pitch plane:
    px_ = f0 * vx + f3 * vy + f6 * vz
    pz_ = e0 * vx + e1 * vy + e2 * vz
    dist = xm.sqrt(px_ * px_ + pz_ * pz_)
    reachable = side_ok & (dist >= k.lo_tol) & (dist <= k.hi_tol)
    s_ = xm.clip(dist, k.lo, k.hi)   # ik.bend(a, b, s_) with t = 0
    out = xm.clip((k.far - s_) * (k.far + s_), 0.0, k.span)
    inn = xm.clip((s_ - k.near) * (s_ + k.near), 0.0, k.span)
    knee = k.kb * (2.0 * xm.atan2(xm.sqrt(out), xm.sqrt(inn)))
    ankle_a = xm.atan2(k.a * xm.sin(knee), k.b + k.a * xm.cos(knee))
    ankle_pitch = -xm.atan2(px_, pz_) - ankle_a
    ankle_pitch = xm.atan2(xm.sin(ankle_pitch), xm.cos(ankle_pitch))
    t = -(ankle_pitch + knee)        # R1 Ry(hip_pitch) = F Rx(-roll) Ry(t)
    ct, st = xm.cos(t), xm.sin(t)
    if k.yaw_roll:
        hip_pitch = xm.atan2(-(ct * f6 - st * e2), st * f6 + ct * e2)
    else:
        hip_pitch = xm.atan2(st * f0 + ct * e0, ct * f0 - st * e0)
    if k.six:
        return LegIK((yaw, hip_roll, hip_pitch, knee, ankle_pitch, roll), reachable)
    return LegIK((yaw, hip_roll, hip_pitch, knee, ankle_pitch, roll - roll), reachable, roll)
