"""One factory picks the bus backend (like pyserial's ``serial_for_url``).

The hardware buses (``dynamixel`` = Protocol 2.0, ``dynamixel1`` = Protocol 1.0,
``feetech``, ``lx`` = HiWonder/LewanSoul LX serial bus servos) are built in. Other kinds are plugins: a
distribution declares an entry point in the group ``biped.buses`` (biped's own
pyproject.toml declares ``sim = "sim:open_bus"``), naming a callable
``(robot, *, port, baud, **options) -> Bus``; ``register_bus`` adds one at run time. So
``robot/`` never imports ``sim/``.
"""

from __future__ import annotations

from collections.abc import Callable
from importlib.metadata import entry_points

from robot.bus.base import Bus
from robot.config.robot import RobotConfig
from robot.errors import ConfigError

#: Entry-point group where bus plugins are declared.
ENTRY_POINT_GROUP = "biped.buses"
#: "lx": the HiWonder/LewanSoul LX servos' own protocol (LX-16A, LX-224, LX-224HV); named
#: after the model prefix users see on the servo (the brand changed from LewanSoul to
#: HiWonder; the errors list every kind).
HARDWARE = ("dynamixel", "dynamixel1", "feetech", "lx")

BusFactory = Callable[..., Bus]   # (robot, *, port: str | None, baud: int | None, **options)

_registered: dict[str, BusFactory] = {}


def register_bus(kind: str, factory: BusFactory) -> None:
    """Make ``make_bus(kind, ...)`` call ``factory(robot, port=..., baud=..., **options)``."""
    if kind in HARDWARE:
        raise ConfigError(f"register_bus: {kind!r} is a built-in bus kind; choose another name")
    _registered[kind] = factory


def bus_kinds() -> tuple[str, ...]:
    """Every bus kind ``make_bus`` accepts: plugins (registered or declared), then hardware."""
    plugins = set(_registered) | {ep.name for ep in entry_points(group=ENTRY_POINT_GROUP)}
    return (*sorted(plugins - set(HARDWARE)), *HARDWARE)


def _plugin(kind: str) -> BusFactory | None:
    if kind not in _registered:
        found = [ep for ep in entry_points(group=ENTRY_POINT_GROUP) if ep.name == kind]
        if not found:
            return None
        try:
            _registered[kind] = found[0].load()
        except ImportError as e:
            raise ConfigError(f"--bus {kind}: plugin {found[0].value} (entry point group "
                              f"{ENTRY_POINT_GROUP}) cannot be imported: {e}") from e
    return _registered[kind]


def make_bus(kind: str | None, *, robot: RobotConfig, port: str | None = None,
             baud: int | None = None, **options: object) -> Bus:
    """A closed bus of ``kind`` (default: the robot config's) for ``robot``'s servos.

    kind: one of ``bus_kinds()`` ("sim", "dynamixel", "feetech" when biped is installed);
    port/baud override the robot config's.
    """
    kind = kind or robot.bus.kind
    if kind in HARDWARE:
        if kind != robot.bus.kind:
            raise ConfigError(f"--bus {kind}: robot {robot.name} ({robot.source}) has "
                              f"{robot.bus.kind} servos; use --bus {robot.bus.kind} or a "
                              f"{kind} robot config")
        port = port or robot.bus.port
        baud = baud or robot.bus.baud
        if kind == "dynamixel":
            from robot.bus.dynamixel.protocol2 import DynamixelBus

            return DynamixelBus(port, baud=baud, robot=robot, **options)  # type: ignore[arg-type]
        if kind == "dynamixel1":
            from robot.bus.dynamixel.protocol1 import Dynamixel1Bus

            return Dynamixel1Bus(port, baud=baud, robot=robot, **options)  # type: ignore[arg-type]
        if kind == "lx":
            from robot.bus.lx.bus import LxBus

            return LxBus(port, baud=baud, robot=robot, **options)  # type: ignore[arg-type]
        from robot.bus.feetech.bus import FeetechBus

        return FeetechBus(port, baud=baud, robot=robot, **options)  # type: ignore[arg-type]
    factory = _plugin(kind)
    if factory is None:
        raise ConfigError(f"--bus: unknown bus {kind!r}; valid: {', '.join(bus_kinds())} "
                          f"(plugins are entry points in group {ENTRY_POINT_GROUP}; "
                          "reinstall biped if 'sim' is missing)")
    return factory(robot, port=port, baud=baud, **options)
