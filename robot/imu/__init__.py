"""IMUs: one interface (base.Imu, samples in the torso frame), tilt estimation for balance,
the ``[imu]`` config, a factory, and the BNO055 driver (robot.imu.bno055)."""

from robot.config.imu_file import ImuConfig, parse_imu
from robot.imu.base import STANDARD_GRAVITY, Imu, ImuError, ImuSample
from robot.imu.factory import open_imu
from robot.imu.frames import Mount
from robot.imu.kinds import imu_kinds, register_imu
from robot.imu.tilt import Tilt, TiltEstimator, tilt_from_accel, tilt_from_quat

__all__ = ["STANDARD_GRAVITY", "Imu", "ImuConfig", "ImuError", "ImuSample", "Mount", "Tilt",
           "TiltEstimator", "imu_kinds", "open_imu", "parse_imu", "register_imu",
           "tilt_from_accel", "tilt_from_quat"]
