"""One factory picks the bus backend (like pyserial's ``serial_for_url``)."""

from __future__ import annotations

from robot.bus.base import Bus
from robot.config import RobotConfig
from robot.errors import ConfigError

KINDS = ("sim", "dynamixel", "feetech")


def make_bus(kind: str | None, *, robot: RobotConfig, port: str | None = None,
             baud: int | None = None, **options: object) -> Bus:
    """A closed bus of ``kind`` (default: the robot config's) for ``robot``'s servos.

    kind: "sim" | "dynamixel" | "feetech"; port/baud override the robot config's.
    """
    kind = kind or robot.bus.kind
    if kind == "sim":
        from sim.mujoco_bus import MujocoBus

        return MujocoBus(robot, **options)  # type: ignore[arg-type]
    if kind in ("dynamixel", "feetech"):
        if kind != robot.bus.kind:
            raise ConfigError(f"--bus {kind}: robot {robot.name} ({robot.source}) has "
                              f"{robot.bus.kind} servos; use --bus {robot.bus.kind} or a "
                              f"{kind} robot config")
        port = port or robot.bus.port
        baud = baud or robot.bus.baud
        if kind == "dynamixel":
            from robot.bus.dynamixel import DynamixelBus

            return DynamixelBus(port, baud=baud, robot=robot, **options)  # type: ignore[arg-type]
        from robot.bus.feetech import FeetechBus

        return FeetechBus(port, baud=baud, robot=robot, **options)  # type: ignore[arg-type]
    raise ConfigError(f"--bus: unknown bus {kind!r}; valid: {', '.join(KINDS)}")
