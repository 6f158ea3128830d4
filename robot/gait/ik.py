"""Analytic IK and FK for the 6-DoF legs and 3-DoF arms (pelvis frame, REP-103).

Leg chain (robot.config.Geometry): hip yaw (z), roll (x), pitch (y) meet at the hip centre
(0, -/+ hip_width/2, 0) for the right/left leg; knee (y) ``thigh`` below; ankle pitch (y)
and roll (x) ``shin`` below the knee; the sole point ``ankle_height`` below the ankle.
The leg IK is the closed form of Kajita et al. ("Introduction to Humanoid Robotics",
sec. 2.5) for a yaw-roll-pitch hip, pitch knee and pitch-roll ankle.

Arm chain: shoulder pitch (y), roll (x) at (0, -/+ shoulder_width/2, torso_height); elbow
(y) ``upper_arm`` below; the hand point ``forearm`` below the elbow.

Every function works on floats (one tick) and on numpy arrays (vectorised). An
unreachable target is clamped to a reachable pose (the nearest one, except in the arm's
lateral caps: see arm_ik): never NaN, never an exception, no division by ~0;
``reachable`` tells which inputs were clamped.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from robot.config.robot import Geometry
from robot.gait import xmath as xm
from robot.gait.xmath import Num, Rot, Vec

SIDE_SIGN = {"r": -1.0, "l": 1.0}  # y sign of the right / left hip and shoulder
#: A target within this distance [m] of the arm's workspace counts as reachable.
REACH_TOL = 1e-12


class LegIK(NamedTuple):
    """Leg joint angles [rad]: hip_yaw, hip_roll, hip_pitch, knee, ankle_pitch, ankle_roll;
    reachable: False (per sample) where the target was clamped; roll_lost: on a leg without
    ankle roll (robot.gait.ik_chain), the roll [rad] of the target foot about its own x
    axis that the leg could not take (target = achieved @ rot_x(roll_lost)); else 0."""

    q: tuple[Num, Num, Num, Num, Num, Num]
    reachable: Num
    roll_lost: Num = 0.0


class ArmIK(NamedTuple):
    """Arm joint angles [rad]: shoulder_pitch, shoulder_roll, elbow; reachable flag."""

    q: tuple[Num, Num, Num]
    reachable: Num


def hip_centre(g: Geometry, side: str) -> Vec:
    return (0.0, SIDE_SIGN[side] * g.hip_width / 2, 0.0)


def shoulder_centre(g: Geometry, side: str) -> Vec:
    return (0.0, SIDE_SIGN[side] * g.shoulder_width / 2, g.torso_height)


def spans(a: float, b: float, s: Num, t: Num = 0.0) -> tuple[Num, Num]:
    """(a + b)^2 - c^2 and c^2 - (a - b)^2 [m^2] for links ``a``, ``b`` [m] whose far ends
    are c = sqrt(s^2 + t^2) [m] apart, c clamped to [|a - b|, a + b] (the two sum to 4ab).
    Written as (|s| -+ L)(|s| +- L) -+ t^2: exact to the last bit when the pair points
    along s (t ~ 0)."""
    far, near, s, t2, span = a + b, abs(a - b), abs(s), t * t, 4.0 * a * b
    return (xm.clip((far - s) * (far + s) - t2, 0.0, span),
            xm.clip((s - near) * (s + near) + t2, 0.0, span))


def bend(a: float, b: float, s: Num, t: Num = 0.0) -> Num:
    """Bend [rad] of the joint between links ``a`` and ``b`` [m] whose far ends are
    sqrt(s^2 + t^2) [m] apart: 0 straight, pi folded, and clamped to those beyond.

    Half-angle law of cosines, tan(bend/2) = sqrt(spans): no acos of a rounded cosine
    (which loses half the digits when nearly straight or folded).
    """
    out, inn = spans(a, b, s, t)
    return 2.0 * xm.atan2(xm.sqrt(out), xm.sqrt(inn))


class Reach(NamedTuple):
    """The distances [m] a two-link chain spans within its middle joint's limits: ``lo``
    at its largest bend, ``hi`` at its smallest."""

    lo: float
    hi: float


def reach(a: float, b: float, bend_lo: float, bend_hi: float) -> Reach:
    """Links ``a``, ``b`` [m] joined by a joint bent between ``bend_lo`` and ``bend_hi``
    [rad] (0 straight, pi folded; a limit beyond those is the geometry's own): their far
    ends are sqrt(a^2 + b^2 + 2ab cos(bend)) [m] apart, exactly a + b and |a - b| at the
    ends of the geometry."""
    def span(bend: float) -> float:
        return math.sqrt(max(a * a + b * b + 2.0 * a * b * math.cos(bend), 0.0))
    lo = abs(a - b) if bend_hi >= math.pi else span(max(bend_hi, 0.0))
    hi = a + b if bend_lo <= 0.0 else span(min(bend_lo, math.pi))
    return Reach(min(lo, hi), hi)


def leg_reach(g: Geometry, knee_lo: float = 0.0, knee_hi: float = math.pi) -> Reach:
    """Hip to ankle distances [m] within the knee's limits [rad] (knee >= 0 bends)."""
    return reach(g.thigh, g.shin, knee_lo, knee_hi)


def arm_reach(g: Geometry, elbow_lo: float = -math.pi, elbow_hi: float = 0.0) -> Reach:
    """Shoulder to hand distances [m] within the elbow's limits [rad] (elbow <= 0 bends)."""
    return reach(g.upper_arm, g.forearm, -elbow_hi, -elbow_lo)


def leg_fk_full(g: Geometry, side: str, q: tuple[Num, ...]) -> tuple[Vec, Rot]:
    """Sole point [m] and foot rotation in the pelvis frame for leg angles ``q`` (6)."""
    hx, hy, hz = hip_centre(g, side)
    r_hip = xm.post_ry(xm.post_rx(xm.rot_z(q[0]), q[1]), q[2])
    r_knee = xm.post_ry(r_hip, q[3])
    r_foot = xm.post_rx(xm.post_ry(r_knee, q[4]), q[5])
    # position = hip + r_hip @ (0,0,-thigh) + r_knee @ (0,0,-shin) + r_foot @ (0,0,-ah)
    x = hx - r_hip[2] * g.thigh - r_knee[2] * g.shin - r_foot[2] * g.ankle_height
    y = hy - r_hip[5] * g.thigh - r_knee[5] * g.shin - r_foot[5] * g.ankle_height
    z = hz - r_hip[8] * g.thigh - r_knee[8] * g.shin - r_foot[8] * g.ankle_height
    return (x, y, z), r_foot


def leg_fk(g: Geometry, side: str, q: np.ndarray) -> np.ndarray:
    """Sole point [m] in the pelvis frame for leg angles ``q`` (6,)."""
    pos, _ = leg_fk_full(g, side, tuple(float(v) for v in q))
    return np.array(pos)


def leg_ik(g: Geometry, side: str, sole: Vec, foot_rot: Rot = xm.IDENTITY, *,
           span: Reach | None = None) -> LegIK:
    """Leg angles [rad] that put the sole point at ``sole`` [m] with foot rotation
    ``foot_rot`` (both in the pelvis frame).

    span: the hip to ankle distances the knee's limits allow (``leg_reach``; None: the
    geometry's, |thigh - shin| to thigh + shin). A target nearer or farther is clamped
    along the ankle → hip line (``reachable`` False): the foot keeps its orientation and
    direction from the hip and the knee stays inside its limits, where clamping the knee
    afterwards would move the foot off that line. Degenerate targets divide by nothing:
    an ankle point at the hip centre folds the knee as far as it may.
    """
    return leg_ik_at(hip_centre(g, side), g.thigh, g.shin, g.ankle_height, sole, foot_rot,
                     span=span)


def leg_ik_at(hip: Vec, a: float, b: float, ankle_height: float, sole: Vec,
              foot_rot: Rot = xm.IDENTITY, *, span: Reach | None = None) -> LegIK:
    """``leg_ik`` for the hip centre ``hip`` [m], thigh ``a``, shin ``b`` and ankle height
    [m] of a leg whose axes meet as the box model's do (robot.body.legs.LegChain.simple)."""
    lo, hi = span if span is not None else (abs(a - b), a + b)
    hx, hy, hz = hip
    # Ankle point: the sole plus the foot's own up vector times the ankle height.
    ax = sole[0] + foot_rot[2] * ankle_height
    ay = sole[1] + foot_rot[5] * ankle_height
    az = sole[2] + foot_rot[8] * ankle_height
    rx, ry, rz = xm.apply_t(foot_rot, (hx - ax, hy - ay, hz - az))  # ankle → hip, foot frame
    c = xm.sqrt(rx * rx + ry * ry + rz * rz)
    reachable = (c >= lo - REACH_TOL) & (c <= hi + REACH_TOL)
    knee = bend(a, b, xm.clip(c, lo, hi))
    # Angle at the ankle between the shin and the ankle → hip line. atan2, not the
    # law-of-sines asin: that one picks the acute branch, wrong when thigh > shin.
    ankle_a = xm.atan2(a * xm.sin(knee), b + a * xm.cos(knee))
    sz_ = xm.sign(rz)
    ankle_roll = xm.atan2(ry * sz_, rz * sz_)  # in (-pi/2, pi/2]
    ankle_pitch = -xm.atan2(rx, sz_ * xm.sqrt(ry * ry + rz * rz)) - ankle_a
    ankle_pitch = xm.atan2(xm.sin(ankle_pitch), xm.cos(ankle_pitch))  # into (-pi, pi]
    # Hip: R = foot_rot @ Rx(-roll) @ Ry(-(pitch + knee)) = Rz(yaw) Rx(roll) Ry(pitch); of
    # R only the entries 1, 4, 6, 7 and 8 are needed (those of xmath.post_rx / post_ry).
    c, s = xm.cos(-ankle_roll), xm.sin(-ankle_roll)
    f = foot_rot
    r1, r4, r7, rx8 = c * f[1] + s * f[2], c * f[4] + s * f[5], c * f[7] + s * f[8], \
        c * f[8] - s * f[7]
    c, s = xm.cos(-(ankle_pitch + knee)), xm.sin(-(ankle_pitch + knee))
    r6, r8 = c * f[6] - s * rx8, s * f[6] + c * rx8
    hip_yaw = xm.atan2(-r1, r4)
    cz, sz = xm.cos(hip_yaw), xm.sin(hip_yaw)
    hip_roll = xm.atan2(r7, -r1 * sz + r4 * cz)
    hip_pitch = xm.atan2(-r6, r8)
    return LegIK((hip_yaw, hip_roll, hip_pitch, knee, ankle_pitch, ankle_roll), reachable)


def arm_fk_local(g: Geometry, q: tuple[Num, Num, Num]) -> Vec:
    """Hand point relative to the shoulder centre for arm angles ``q``."""
    s1, c1 = xm.sin(q[0]), xm.cos(q[0])
    s2, c2 = xm.sin(q[1]), xm.cos(q[1])
    vx = -g.forearm * xm.sin(q[2])
    vz = -g.upper_arm - g.forearm * xm.cos(q[2])
    return (c1 * vx + s1 * c2 * vz, -s2 * vz, -s1 * vx + c1 * c2 * vz)


def arm_fk(g: Geometry, side: str, q: np.ndarray) -> np.ndarray:
    """Hand point [m] in the pelvis frame for arm angles ``q`` (3,)."""
    local = arm_fk_local(g, (float(q[0]), float(q[1]), float(q[2])))
    return np.add(local, shoulder_centre(g, side))


def arm_ik(g: Geometry, hand: Vec, *, span: Reach | None = None) -> ArmIK:
    """Arm angles [rad] putting the hand point at ``hand`` [m] relative to the shoulder centre.

    span: the distances the elbow's limits allow (``arm_reach``; None: the geometry's
    annulus |f - u| to u + f); "the annulus" below is this one.

    The elbow (bent forward, <= 0) sets the distance d; in the elbow's plane the hand is
    then at (vx, vz) = (-f sin(elbow), -u - f cos(elbow)) [m], and the roll about x sends it
    to y = -sin(roll) vz. So the workspace is not the whole annulus |f - u| <= d <= u + f:
    at distance d the hand reaches only |y| <= |vz| = |d^2 + u^2 - f^2| / (2u). With
    forearm f > upper arm u, vz = 0 at d0 = sqrt(f^2 - u^2) (forearm square to the upper
    arm, hand on the roll axis): there only y = 0 is reachable (the singular circle), and a
    hand held |y| = 1 cm out of the shoulder plane cannot come nearer than
    sqrt(f^2 - u^2 + 2u|y|) (5.7 cm on the shipped robots).

    Clamping (``reachable`` False; never NaN, no division by ~0):
    - outside the annulus: radially onto it, which is the nearest reachable point;
    - inside it but out of lateral reach (|y| > |vz|): the hand keeps d and its direction
      about the pitch axis, and sin(roll) = -vz / y, the reciprocal of the exact -y / vz.
      The roll is +-90 deg at the edge of reach and passes through 0 at the singular
      sphere, so it is continuous there. (The nearest point is not: it jumps between the
      two lobes of the workspace and the roll flips by pi.) The hand lands at
      |y| = vz^2 / |y_target|.
    Where an angle does not matter, it takes its neutral value: roll 0 on the singular
    circle (vz = y = 0), shoulder pitch 0 for a target or hand on the pitch axis (y).
    Jumps remain only where no stateless IK avoids them: across the pitch axis, and right
    at the singular circle (reachable targets beside it need every roll in +-90 deg, at
    joint rates ~ 1 / their distance from it). The roll stays within +-90 deg; the pitch
    is in (-pi, pi].
    """
    u, f = g.upper_arm, g.forearm
    px, py, pz = hand
    rho2 = px * px + pz * pz  # squared distance from the pitch axis
    d = xm.sqrt(rho2 + py * py)
    lo, hi = span if span is not None else (abs(u - f), u + f)
    dc = xm.clip(d, lo, hi)
    k = dc / xm.maximum(d, 1e-300)  # radially onto the annulus (1 exactly inside it)
    y = xm.clip(py * k, -dc, dc)
    out, inn = spans(u, f, py * k, xm.sqrt(rho2) * k)  # and onto the geometry's
    elbow = -2.0 * xm.atan2(xm.sqrt(out), xm.sqrt(inn))
    # The hand in the elbow's plane, by algebra (the same bits on floats and arrays):
    vx = xm.sqrt(out * inn) / (2.0 * u)  # -f sin(elbow) >= 0
    vz = (f - u) - inn / (2.0 * u)  # -u - f cos(elbow)
    # sin(roll) = -y/vz within reach, -vz/y beyond it: atan2(-+min(|y|, |vz|),
    # sqrt(|vz^2 - y^2|)), no asin of a rounded sine, 0 where both are 0. vz^2 - y^2 =
    # rho^2 - vx^2 (= d^2 - vx^2 - y^2); each form is exact to ~eps * its larger operand,
    # so they are weighed towards the smaller (rho on the pitch axis, vz near d0).
    ay, az, rr, zz = abs(y), abs(vz), rho2 * k * k, vz * vz
    lat2 = (zz * (rr - vx * vx) + rr * (az - ay) * (az + ay)) / xm.maximum(rr + zz, 1e-300)
    roll = xm.atan2(-xm.sign(y) * xm.sign(vz) * 0.5 * (ay + az - abs(ay - az)),
                    xm.sqrt(abs(lat2)))
    w = xm.cos(roll) * vz
    # pitch = atan2(px, pz) - atan2(vx, w), as one atan2: 0 when either vector is zero.
    pitch = xm.atan2(px * w - pz * vx, pz * w + px * vx + 0.0)
    reachable = (d >= lo - REACH_TOL) & (d <= hi + REACH_TOL) & (ay <= az + REACH_TOL)
    return ArmIK((pitch, roll, elbow), reachable)
