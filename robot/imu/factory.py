"""One factory picks the IMU backend by ``ImuConfig.kind`` (like ``robot.bus.factory``).

``bno055`` (robot.imu.bno055, BNO055 over UART) is built in. Other kinds are plugins: a
distribution declares an entry point in the group ``biped.imus`` (biped's own
pyproject.toml declares ``sim = "sim.mujoco.imu:open_sim_imu"``), naming a callable
``(config: ImuConfig, *, bus: Bus | None) -> Imu``; ``register_imu`` adds one at run time.
So ``robot/`` never imports ``sim/``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from robot.config.imu_file import ENTRY_POINT_GROUP, ImuConfig, imu_kinds
from robot.errors import ConfigError
from robot.imu.base import Imu
from robot.imu.kinds import plugin

if TYPE_CHECKING:
    from robot.bus.base import Bus

def open_imu(config: ImuConfig, *, bus: Bus | None = None) -> Imu:
    """The IMU backend for ``config`` (not yet opened: use ``with open_imu(...) as imu:``).

    bus: the servo bus the robot runs on; the ``sim`` IMU reads the MuJoCo state of a
    ``sim`` bus (open it first), real IMUs ignore it.
    """
    if config.kind == "bno055":
        from robot.imu.bno055 import Bno055Imu

        return Bno055Imu(config)
    factory = plugin(config.kind)
    if factory is None:
        raise ConfigError(f"imu.kind: unknown IMU {config.kind!r}; valid: "
                          f"{', '.join(imu_kinds())} (plugins are entry points in group "
                          f"{ENTRY_POINT_GROUP}; reinstall biped if 'sim' is missing)")
    imu = factory(config, bus=bus)
    if not isinstance(imu, Imu):
        raise ConfigError(f"imu.kind {config.kind}: its plugin returned a "
                          f"{type(imu).__name__}, not an IMU (robot.imu.base.Imu)")
    return imu
