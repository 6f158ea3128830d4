"""Options that turn the balance feedback on or off (`walk`, `panel`) and build it: on by
default when the robot file has an ``[imu]``, ``--no-balance`` for the paper's open-loop
gait exactly."""

from __future__ import annotations

import argparse
import dataclasses
import logging
from collections.abc import Callable

from robot.balance.stage import Balance, attitude_reader
from robot.bus.base import Bus
from robot.commands.common import bounded_float
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.imu import Imu, open_imu

log = logging.getLogger(__name__)

#: --imu-noise: scale of the sim IMU's datasheet noise and offsets.
IMU_NOISE = (0.0, 10.0)


def add_balance_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--no-balance", action="store_true",
                   help="open loop: the paper's gait exactly, no IMU feedback (default: "
                        "balance on when the robot file has an [imu])")
    p.add_argument("--imu-noise", type=bounded_float(*IMU_NOISE, "x"), default=None,
                   metavar="SCALE", help="sim IMU noise and offsets x the BNO055 datasheet's "
                                         "(default: the robot file's imu.noise/imu.bias)")


def imu_for(args: argparse.Namespace, robot: RobotConfig, bus: Bus) -> Imu | None:
    """The robot's IMU (not opened) when balance is on, else None."""
    if args.no_balance or robot.imu is None:
        if robot.imu is None and not args.no_balance:
            log.info("%s has no [imu]: walking open loop", robot.name)
        return None
    config = robot.imu
    if config.kind == "sim" and bus.kind != "sim":
        # The bundled robots simulate their IMU: on real servos there is none to read.
        log.warning("%s: imu.kind is \"sim\", which only exists in simulation: walking open "
                    "loop on the %s bus (set [imu] kind to your device, docs/imu.md)",
                    robot.source, bus.kind)
        return None
    if args.imu_noise is not None:
        if config.kind != "sim":
            raise ConfigError(f"--imu-noise applies to a simulated IMU; {robot.source}: "
                              f"imu.kind is {config.kind!r}")
        config = dataclasses.replace(config, noise=args.imu_noise, bias=args.imu_noise)
    return open_imu(config, bus=bus)


def feedback_factory(imu: Imu | None) -> Callable[[GaitEngine], Balance | None] | None:
    """For the panel: per run, open ``imu`` if needed (after the bus) and build the stage."""
    if imu is None:
        return None
    device = imu

    def make(engine: GaitEngine) -> Balance | None:
        if not device.is_open:
            device.open()
        return balance_for(device, engine)
    return make


def balance_for(imu: Imu | None, engine: GaitEngine) -> Balance | None:
    """The streamer's feedback stage reading the opened ``imu`` (None: open loop)."""
    return None if imu is None else Balance(engine, attitude_reader(imu))
