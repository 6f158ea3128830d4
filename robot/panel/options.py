"""What the panel's loop process is made of, as data it can be sent (robot.panel.loop):
the robot, how to build its bus, the parameters and the loop's options; and the error for
a request that does not fit the loop's state."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from robot.bus.base import Bus
from robot.bus.factory import make_bus
from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.errors import BipedError


class PanelStateError(BipedError):
    """The request does not fit the loop's state (e.g. start while running): 409."""


@dataclass(frozen=True)
class LoopOptions:
    """rate_hz: control rate [Hz]; read_every: read back every N ticks; hold: keep torque
    on at the rest pose after a stop; balance: IMU feedback for each run when the robot
    has an ``[imu]``; imu_noise: a simulated IMU's noise scale (None: the robot file's);
    mcap: each recorded take also writes NAME.mcap beside it (robot/loop/mcap_recorder.py)."""

    rate_hz: float = 200.0
    read_every: int = 10
    hold: bool = False
    balance: bool = False
    imu_noise: float | None = None
    mcap: bool = False


#: The options of a panel given none.
DEFAULT_OPTIONS = LoopOptions()


@dataclass(frozen=True)
class BusSpec:
    """How to build the bus where the loop runs: ``make_bus(kind, port=, baud=,
    **options)`` (e.g. ``BusSpec("sim", options={"realtime": True})``)."""

    kind: str
    port: str | None = None
    baud: int | None = None
    options: Mapping[str, object] = field(default_factory=dict)

    def build(self, robot: RobotConfig) -> Bus:
        return make_bus(self.kind, robot=robot, port=self.port, baud=self.baud,
                        **dict(self.options))


@dataclass(frozen=True)
class HostSpec:
    """Everything the loop process needs to start: the robot, its bus, the parameters of
    the first run, the loop's options."""

    robot: RobotConfig
    bus: BusSpec
    params: GaitParams
    options: LoopOptions = DEFAULT_OPTIONS
