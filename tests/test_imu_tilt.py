"""Rotations, tilt conventions and the complementary filter against analytic cases."""

from __future__ import annotations

import math

import pytest

from robot.imu import STANDARD_GRAVITY, ImuSample, Mount, TiltEstimator, tilt_from_accel, tilt_from_quat
from robot.imu.frames import quat_conj, quat_from_rpy, quat_rotate
from robot.imu.tilt import DEFAULT_TAU_S

G = STANDARD_GRAVITY


def still_accel(roll: float, pitch: float, yaw: float = 0.0) -> tuple[float, float, float]:
    """What a still accelerometer reads: world +z (g) seen from the torso."""
    return quat_rotate(quat_conj(quat_from_rpy(roll, pitch, yaw)), (0.0, 0.0, G))


@pytest.mark.parametrize("roll,pitch,yaw", [(0.0, 0.0, 0.0), (0.3, 0.0, 0.0), (0.0, 0.3, 0.0),
                                            (-0.2, 0.4, 1.0), (0.5, -0.7, -2.5)])
def test_tilt_from_quat_and_accel_give_roll_and_pitch(roll: float, pitch: float,
                                                      yaw: float) -> None:
    t = tilt_from_quat(quat_from_rpy(roll, pitch, yaw))
    assert t.roll == pytest.approx(roll, abs=1e-12) and t.pitch == pytest.approx(pitch, abs=1e-12)
    a = tilt_from_accel(still_accel(roll, pitch, yaw))
    assert a.roll == pytest.approx(roll, abs=1e-12) and a.pitch == pytest.approx(pitch, abs=1e-12)


def test_positive_pitch_is_nose_down_about_plus_y() -> None:
    """REP-103: +pitch is a right-hand rotation about +y: x (forward) tips toward -z."""
    q = quat_from_rpy(0.0, 0.2, 0.0)
    nose = quat_rotate(q, (1.0, 0.0, 0.0))
    assert nose[2] < 0                       # the nose points down
    assert tilt_from_quat(q).pitch > 0
    assert still_accel(0.0, 0.2)[0] < 0      # "up" is behind the tipped x axis
    # +roll (about +x): y (left) tips up, the robot leans to its right.
    assert quat_rotate(quat_from_rpy(0.2, 0.0, 0.0), (0.0, 1.0, 0.0))[2] > 0


def test_mount_rotates_into_the_torso_frame_and_back() -> None:
    m = Mount.from_rpy_deg((0.0, 0.0, 90.0))  # chip x points to the robot's left
    s = ImuSample(1.0, (0.1, 0.0, 0.0), (0.0, 0.0, G), quat_from_rpy(0.1, 0.2, 0.3))
    dev = m.to_imu(s)
    assert dev.gyro == pytest.approx((0.0, -0.1, 0.0), abs=1e-12)
    back = m.to_torso(dev)
    assert back.gyro == pytest.approx(s.gyro, abs=1e-12)
    assert back.accel == pytest.approx(s.accel, abs=1e-12)
    assert back.quat == pytest.approx(s.quat, abs=1e-12)
    assert Mount().to_torso(s) is s


def sample(t: float, gyro: tuple[float, float, float] = (0.0, 0.0, 0.0),
           pitch: float = 0.0, roll: float = 0.0) -> ImuSample:
    return ImuSample(t, gyro, still_accel(roll, pitch))


def test_filter_tracks_a_consistent_rotation_exactly() -> None:
    """Gyro and accelerometer agree (pitch = w t): the estimate is w t at every step."""
    w, dt = 0.4, 0.01
    est = TiltEstimator()
    for n in range(200):
        tilt = est.update(sample(n * dt, (0.0, w, 0.0), pitch=w * n * dt))
        assert tilt.pitch == pytest.approx(w * n * dt, abs=1e-12)
        assert tilt.roll == pytest.approx(0.0, abs=1e-12)


def test_filter_accel_step_is_first_order_with_time_constant_tau() -> None:
    """No rotation, accelerometer steps to pitch p: estimate p (1 - a^n), a = tau/(tau+dt)."""
    p, dt, tau = 0.2, 0.005, 0.5
    est = TiltEstimator(tau_s=tau)
    est.update(sample(0.0))
    a = tau / (tau + dt)
    for n in range(1, 401):
        tilt = est.update(sample(n * dt, pitch=p))
        assert tilt.pitch == pytest.approx(p * (1 - a ** n), abs=1e-12)
    # After tau the filter has closed ~63 % of the step.
    assert p * (1 - a ** round(tau / dt)) == pytest.approx(p * (1 - math.exp(-1)), rel=0.01)


def test_filter_gyro_bias_leaves_bias_times_tau() -> None:
    b, dt = 0.02, 0.01
    est = TiltEstimator()
    for n in range(3000):
        tilt = est.update(sample(n * dt, (0.0, b, 0.0)))
    assert tilt.pitch == pytest.approx(b * DEFAULT_TAU_S, rel=1e-6)


def test_filter_ignores_accel_in_free_fall_and_uses_quat() -> None:
    est = TiltEstimator()
    est.update(sample(0.0))
    tilt = est.update(ImuSample(0.1, (0.5, 0.0, 0.0), (0.0, 0.0, 0.0)))  # free fall
    assert tilt.roll == pytest.approx(0.05, abs=1e-12)
    assert est.update(ImuSample(0.1, (9.0, 0.0, 0.0), (0.0, 0.0, G))) == tilt  # dt = 0
    q = quat_from_rpy(0.1, -0.2, 0.0)
    with_quat = est.update(ImuSample(0.2, (0.0, 0.0, 0.0), (0.0, 0.0, G), q))
    assert with_quat.pitch == pytest.approx(-0.2) and with_quat.roll == pytest.approx(0.1)
    gap = est.update(sample(5.0, pitch=0.3))   # a long gap restarts from the accelerometer
    assert gap.pitch == pytest.approx(0.3)
    with pytest.raises(ValueError):
        TiltEstimator(tau_s=0.0)
