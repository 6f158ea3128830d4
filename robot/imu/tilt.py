"""Tilt (roll, pitch) of the torso for a balance controller: from a fused quaternion, from
the accelerometer alone, or from gyro + accelerometer with a complementary filter.

Angles (REP-103 torso frame, x forward, y left, z up; the ZYX / roll-pitch-yaw convention of
``robot.imu.frames``): roll is the rotation about +x (positive: left side up, leaning to the
right); pitch is the rotation about +y (positive: nose down, leaning forward). Both [rad].
"""

from __future__ import annotations

import math
from typing import NamedTuple

from robot.imu.base import STANDARD_GRAVITY, ImuSample, Quat, Vec3

#: Default time constant of the complementary filter [s]: the accelerometer corrects the
#: integrated gyro with this time constant. Longer rejects more of the walking sway the
#: accelerometer sees (a 1 Hz step sway is attenuated ~6x at 1 s); shorter follows a gyro
#: bias less: a constant gyro bias b [rad/s] leaves a steady tilt error of b * tau [rad].
DEFAULT_TAU_S = 1.0
#: The accelerometer corrects only while |accel| is within this band around g (x g): in
#: free fall or at a foot impact it does not point along gravity.
ACCEL_TRUST = (0.5, 1.5)
#: A gap between samples longer than this [s] restarts the filter from the accelerometer.
MAX_GAP_S = 0.5


class Tilt(NamedTuple):
    """roll: about +x, left side up; pitch: about +y, nose down [rad] (module docstring)."""

    roll: float
    pitch: float


def tilt_from_quat(q: Quat) -> Tilt:
    """Roll and pitch [rad] of the orientation ``q`` (w, x, y, z; torso in world)."""
    w, x, y, z = q
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    return Tilt(roll, pitch)


def tilt_from_accel(accel: Vec3) -> Tilt:
    """Roll and pitch [rad] from the specific force [m/s^2] of a still torso (it points
    along world +z seen from the torso: (-sin p, cos p sin r, cos p cos r) * g)."""
    ax, ay, az = accel
    return Tilt(math.atan2(ay, az), math.atan2(-ax, math.hypot(ay, az)))


def euler_rates(tilt: Tilt, gyro: Vec3) -> Tilt:
    """d(roll)/dt, d(pitch)/dt [rad/s] from the body rates ``gyro`` [rad/s] (ZYX kinematics)."""
    p, q, r = gyro
    sr, cr = math.sin(tilt.roll), math.cos(tilt.roll)
    cp = math.cos(tilt.pitch)
    tp = math.sin(tilt.pitch) / cp if abs(cp) > 1e-6 else 0.0
    return Tilt(p + tp * (q * sr + r * cr), q * cr - r * sr)


class TiltEstimator:
    """Complementary filter for roll and pitch from gyro + accelerometer.

    Each update integrates the gyro (as Euler rates) over the time since the last sample
    and blends in the accelerometer's tilt: ``x = a (x + rate dt) + (1 - a) x_accel`` with
    ``a = tau / (tau + dt)``, a first-order low pass of time constant ``tau_s`` [s] on the
    accelerometer and a high pass on the gyro. With ``use_quat`` a sample that carries a
    fused quaternion is taken as is (the device's own filter is better informed).

    The first sample (or one after a gap over MAX_GAP_S) starts from the accelerometer.
    The accelerometer is ignored while |accel| is outside ACCEL_TRUST x g.
    """

    def __init__(self, *, tau_s: float = DEFAULT_TAU_S, use_quat: bool = True) -> None:
        if not tau_s > 0:
            raise ValueError(f"TiltEstimator: tau_s must be > 0 s, got {tau_s}")
        self.tau_s = tau_s
        self.use_quat = use_quat
        self._tilt: Tilt | None = None
        self._t = 0.0

    @property
    def tilt(self) -> Tilt | None:
        """The latest estimate [rad], None before the first update."""
        return self._tilt

    def reset(self) -> None:
        self._tilt = None

    def update(self, sample: ImuSample) -> Tilt:
        """Fold in one sample; returns the new estimate [rad]. A sample not newer than
        the last one (dt <= 0) leaves the estimate unchanged."""
        if self.use_quat and sample.quat is not None:
            self._tilt, self._t = tilt_from_quat(sample.quat), sample.t
            return self._tilt
        dt = sample.t - self._t
        if self._tilt is None or dt > MAX_GAP_S:
            self._tilt, self._t = tilt_from_accel(sample.accel), sample.t
            return self._tilt
        if dt <= 0:
            return self._tilt
        rate = euler_rates(self._tilt, sample.gyro)
        roll = self._tilt.roll + rate.roll * dt
        pitch = self._tilt.pitch + rate.pitch * dt
        g = math.sqrt(sum(c * c for c in sample.accel)) / STANDARD_GRAVITY
        if ACCEL_TRUST[0] <= g <= ACCEL_TRUST[1]:
            a = self.tau_s / (self.tau_s + dt)
            meas = tilt_from_accel(sample.accel)
            roll = a * roll + (1 - a) * (roll + wrap(meas.roll - roll))
            pitch = a * pitch + (1 - a) * meas.pitch
        self._tilt, self._t = Tilt(wrap(roll), pitch), sample.t
        return self._tilt


def wrap(angle: float) -> float:
    """``angle`` wrapped into [-pi, pi) [rad]."""
    return angle - 2 * math.pi * math.floor((angle + math.pi) / (2 * math.pi))
