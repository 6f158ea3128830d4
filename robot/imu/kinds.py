"""Which IMU kinds exist: the built-in ones and the plugins (entry point group
``biped.imus``, or registered at run time). A leaf of ``robot.imu``: the robot file's
``[imu]`` check (robot/imu/config.py) and the factory (robot/imu/factory.py) both ask it.
"""

from __future__ import annotations

from collections.abc import Callable

from robot.imu.base import Imu
from robot.imu.registry import Registry

#: Entry-point group where IMU plugins are declared.
ENTRY_POINT_GROUP = "biped.imus"
BUILTIN = ("bno055",)

ImuFactory = Callable[..., Imu]   # (config: ImuConfig, *, bus: Bus | None) -> Imu

_plugins: Registry[ImuFactory] = Registry(ENTRY_POINT_GROUP, BUILTIN, "imu.kind")


def register_imu(kind: str, factory: ImuFactory) -> None:
    """Make ``open_imu`` build IMUs of ``kind`` with ``factory(config, bus=...)``."""
    _plugins.register(kind, factory)


def imu_kinds() -> tuple[str, ...]:
    """Every IMU kind ``open_imu`` accepts: plugins (registered or declared), then built-in."""
    return _plugins.kinds()


def plugin(kind: str) -> ImuFactory | None:
    """The factory of plugin ``kind`` (loading its entry point), None if unknown."""
    return _plugins.plugin(kind)
