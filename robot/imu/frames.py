"""Rotations for IMU data: quaternions (w, x, y, z), roll-pitch-yaw, and the mounting of an
IMU on the torso.

Conventions: a rotation R maps vectors of frame B into frame A (``v_A = R v_B``); its
quaternion is Hamilton (w, x, y, z). roll-pitch-yaw (rpy) as in URDF: R = Rz(yaw) Ry(pitch)
Rx(roll), angles about the fixed x, y, z axes in that order.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from robot.imu.base import ImuSample, Quat, Vec3


def quat_mul(a: Quat, b: Quat) -> Quat:
    """Hamilton product a ⊗ b (rotation b, then a)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw)


def quat_conj(q: Quat) -> Quat:
    """Conjugate (the inverse of a unit quaternion)."""
    return (q[0], -q[1], -q[2], -q[3])


def quat_normalize(q: Quat) -> Quat:
    w, x, y, z = q
    n = math.sqrt(sum((w * w, x * x, y * y, z * z)))
    if n == 0.0:
        return (1.0, 0.0, 0.0, 0.0)
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


def quat_from_rpy(roll: float, pitch: float, yaw: float) -> Quat:
    """Quaternion of Rz(yaw) Ry(pitch) Rx(roll) [rad]."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (cy * cp * cr + sy * sp * sr,
            cy * cp * sr - sy * sp * cr,
            cy * sp * cr + sy * cp * sr,
            sy * cp * cr - cy * sp * sr)


def quat_rotate(q: Quat, v: Vec3) -> Vec3:
    """R(q) v."""
    w, x, y, z = q
    vx, vy, vz = v
    # t = 2 (q_vec × v); v' = v + w t + q_vec × t
    tx, ty, tz = 2 * (y * vz - z * vy), 2 * (z * vx - x * vz), 2 * (x * vy - y * vx)
    return (vx + w * tx + y * tz - z * ty,
            vy + w * ty + z * tx - x * tz,
            vz + w * tz + x * ty - y * tx)


class Mount(NamedTuple):
    """How an IMU sits on the torso: ``q`` rotates IMU-frame vectors into the torso frame
    (``v_torso = R(q) v_imu``). Identity when the chip's axes are the torso's."""

    q: Quat = (1.0, 0.0, 0.0, 0.0)

    @classmethod
    def from_rpy_deg(cls, rpy_deg: tuple[float, float, float]) -> Mount:
        """From ``mount_rpy_deg`` [deg]: roll, pitch, yaw of the IMU frame in the torso
        frame (URDF convention, see the module docstring)."""
        r, p, y = (math.radians(a) for a in rpy_deg)
        return cls(quat_from_rpy(r, p, y))

    @property
    def is_identity(self) -> bool:
        return self.q == (1.0, 0.0, 0.0, 0.0)

    def to_torso(self, s: ImuSample) -> ImuSample:
        """A sample in the IMU frame → the same measurement in the torso frame. The device
        quaternion (IMU frame in world) becomes the torso's: q_world_torso = q ⊗ conj(mount)."""
        if self.is_identity:
            return s
        quat = None if s.quat is None else quat_normalize(quat_mul(s.quat, quat_conj(self.q)))
        return ImuSample(s.t, quat_rotate(self.q, s.gyro), quat_rotate(self.q, s.accel), quat)

    def to_imu(self, s: ImuSample) -> ImuSample:
        """The inverse of ``to_torso`` (what a rotated chip measures; used by the sim)."""
        if self.is_identity:
            return s
        inv = quat_conj(self.q)
        quat = None if s.quat is None else quat_normalize(quat_mul(s.quat, self.q))
        return ImuSample(s.t, quat_rotate(inv, s.gyro), quat_rotate(inv, s.accel), quat)
