"""Analytic IK and FK for the 6-DoF legs and 3-DoF arms (pelvis frame, REP-103).

Leg chain (robot.config.Geometry): hip yaw (z), roll (x), pitch (y) meet at the hip centre
(0, -/+ hip_width/2, 0) for the right/left leg; knee (y) ``thigh`` below; ankle pitch (y)
and roll (x) ``shin`` below the knee; the sole point ``ankle_height`` below the ankle.
The leg IK is the closed form of Kajita et al. ("Introduction to Humanoid Robotics",
sec. 2.5) for a yaw-roll-pitch hip, pitch knee and pitch-roll ankle.

Arm chain: shoulder pitch (y), roll (x) at (0, -/+ shoulder_width/2, torso_height); elbow
(y) ``upper_arm`` below; the hand point ``forearm`` below the elbow.

Every function works on floats (one tick) and on numpy arrays (vectorised). An
unreachable target is clamped to the nearest reachable pose: never NaN, never an
exception; ``reachable`` tells which inputs were clamped.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from robot import xmath as xm
from robot.config import Geometry
from robot.xmath import Num, Rot, Vec

SIDE_SIGN = {"r": -1.0, "l": 1.0}  # y sign of the right / left hip and shoulder


class LegIK(NamedTuple):
    """Leg joint angles [rad]: hip_yaw, hip_roll, hip_pitch, knee, ankle_pitch, ankle_roll;
    reachable: False (per sample) where the target was clamped."""

    q: tuple[Num, Num, Num, Num, Num, Num]
    reachable: Num


class ArmIK(NamedTuple):
    """Arm joint angles [rad]: shoulder_pitch, shoulder_roll, elbow; reachable flag."""

    q: tuple[Num, Num, Num]
    reachable: Num


def hip_centre(g: Geometry, side: str) -> Vec:
    return (0.0, SIDE_SIGN[side] * g.hip_width / 2, 0.0)


def shoulder_centre(g: Geometry, side: str) -> Vec:
    return (0.0, SIDE_SIGN[side] * g.shoulder_width / 2, g.torso_height)


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


def leg_ik(g: Geometry, side: str, sole: Vec, foot_rot: Rot = xm.IDENTITY) -> LegIK:
    """Leg angles that put the sole point at ``sole`` [m] with foot rotation ``foot_rot``
    (both in the pelvis frame)."""
    a, b = g.thigh, g.shin
    hx, hy, hz = hip_centre(g, side)
    # Ankle point: the sole plus the foot's own up vector times the ankle height.
    ax = sole[0] + foot_rot[2] * g.ankle_height
    ay = sole[1] + foot_rot[5] * g.ankle_height
    az = sole[2] + foot_rot[8] * g.ankle_height
    rx, ry, rz = xm.apply_t(foot_rot, (hx - ax, hy - ay, hz - az))  # ankle → hip, foot frame
    c = xm.maximum(xm.sqrt(rx * rx + ry * ry + rz * rz), 1e-9)
    c_knee = (c * c - a * a - b * b) / (2.0 * a * b)
    reachable = (c_knee <= 1.0) & (c_knee >= -1.0)
    knee = xm.acos(c_knee)
    # Angle at the ankle between the shin and the ankle → hip line. atan2, not the
    # law-of-sines asin: that one picks the acute branch, wrong when thigh > shin.
    ankle_a = xm.atan2(a * xm.sin(knee), b + a * xm.cos(knee))
    sz_ = xm.sign(rz)
    ankle_roll = xm.atan2(ry * sz_, rz * sz_)  # in (-pi/2, pi/2]
    ankle_pitch = -xm.atan2(rx, sz_ * xm.sqrt(ry * ry + rz * rz)) - ankle_a
    # Hip: R = foot_rot @ Rx(-roll) @ Ry(-(pitch + knee)) = Rz(yaw) Rx(roll) Ry(pitch).
    r = xm.post_ry(xm.post_rx(foot_rot, -ankle_roll), -(ankle_pitch + knee))
    hip_yaw = xm.atan2(-r[1], r[4])
    cz, sz = xm.cos(hip_yaw), xm.sin(hip_yaw)
    hip_roll = xm.atan2(r[7], -r[1] * sz + r[4] * cz)
    hip_pitch = xm.atan2(-r[6], r[8])
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


def arm_ik(g: Geometry, hand: Vec) -> ArmIK:
    """Arm angles putting the hand point at ``hand`` [m] relative to the shoulder centre.

    The elbow bends forward (negative angle); the shoulder roll stays within ±90°.
    """
    u, f = g.upper_arm, g.forearm
    px, py, pz = hand
    d = xm.maximum(xm.sqrt(px * px + py * py + pz * pz), 1e-12)
    c_elbow = (d * d - u * u - f * f) / (2.0 * u * f)
    reachable = (c_elbow <= 1.0) & (c_elbow >= -1.0)
    # Unreachable: aim at the nearest reachable point along the shoulder → hand line.
    k = xm.clip(d, abs(u - f), u + f) / d
    px, py, pz = px * k, py * k, pz * k
    elbow = -xm.acos(c_elbow)
    vx = -f * xm.sin(elbow)
    vz = -u - f * xm.cos(elbow)  # < 0 for every elbow angle when f < u + f
    s2 = xm.clip(-py / vz, -1.0, 1.0)
    roll = xm.asin(s2)
    w = xm.cos(roll) * vz
    pitch = xm.atan2(px, pz) - xm.atan2(vx, w)
    pitch = xm.atan2(xm.sin(pitch), xm.cos(pitch))  # wrap to (-pi, pi]
    return ArmIK((pitch, roll, elbow), reachable)
