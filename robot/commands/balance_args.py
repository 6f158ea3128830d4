"""Options that turn the balance feedback on or off (`walk`, `panel`) and build it: on by
default when the robot file has an ``[imu]``, ``--no-balance`` for the paper's open-loop
gait exactly."""

from __future__ import annotations

import argparse
import logging
from collections.abc import Callable

from robot.balance.stage import Balance, attitude_reader
from robot.bus.base import Bus
from robot.commands.common import bounded_float
from robot.config.robot import RobotConfig
from robot.gait.engine import GaitEngine
from robot.imu import Imu
from robot.run.walk import walk_imu

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
    """The robot's IMU (not opened) when balance is on, else None (robot.run.walk)."""
    return walk_imu(robot, bus, balance=not args.no_balance, noise=args.imu_noise)


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
