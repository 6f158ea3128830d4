"""Registering an IMU backend at run time (``register_imu``) and finding a plugin's
factory. The names themselves live with the robot file's ``[imu]`` check
(``robot.config.imu_file.IMU_BACKENDS``), which must know them without importing the IMUs.
"""

from __future__ import annotations

from collections.abc import Callable

from robot.config.imu_file import IMU_BACKENDS, imu_kinds
from robot.imu.base import Imu

__all__ = ["ImuFactory", "imu_kinds", "plugin", "register_imu"]

ImuFactory = Callable[..., Imu]   # (config: ImuConfig, *, bus: Bus | None) -> Imu


def register_imu(kind: str, factory: ImuFactory) -> None:
    """Make ``open_imu`` build IMUs of ``kind`` with ``factory(config, bus=...)``."""
    IMU_BACKENDS.register(kind, factory)


def plugin(kind: str) -> Callable[..., object] | None:
    """The factory of plugin ``kind`` (loading its entry point), None if unknown."""
    return IMU_BACKENDS.plugin(kind)
