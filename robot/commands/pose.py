"""`biped pose rest|zero`: ramp smoothly from where the robot is to a named pose, then hold.

Runs the one streaming loop (``Streamer.run`` of a ``PoseMove``): reads the present pose, refuses to start
if a joint is outside its limits, sets goal := present and torque on (no snap to a stale
goal), then a minimum-jerk ramp at a fixed rate on absolute deadlines, clamped and
slew-limited, with the watchdog. Torque stays ON at the end. Ctrl-C (or SIGTERM) stops the
ramp and holds where it is; a second one before the command ends, or any fault, turns
torque off.
"""

from __future__ import annotations

import argparse
import logging

import numpy as np
import numpy.typing as npt

from robot.bus.servo_map import ServoMap
from robot.commands.common import (
    add_bus_args,
    add_robot_args,
    bus_from,
    joint_speed,
    rate_hz,
    robot_from,
)
from robot.config.robot import RobotConfig
from robot.motion.posing import PoseMove
from robot.run.result import torque_words
from robot.run.run import Run
from robot.run.spec import RunOptions, RunSpec

log = logging.getLogger(__name__)

POSES = ("rest", "zero")


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser("pose", help="ramp to the rest or zero pose and hold it",
                              description=__doc__)
    p.add_argument("pose", choices=POSES, help="rest: the robot config's [rest]; zero: all 0")
    add_robot_args(p, gait=False)
    add_bus_args(p)
    p.add_argument("--rate", type=rate_hz, default=50.0, help="goal rate [Hz]")
    p.add_argument("--speed", type=joint_speed, default=1.0,
                   help="peak joint speed [rad/s], capped by each joint's max_speed_rad_s")
    return p


def pose_target(robot: RobotConfig, name: str, servo_map: ServoMap) -> npt.NDArray[np.float64]:
    """Joint angles [rad] of pose ``name`` (rest: missing joints 0), inside the limits."""
    q = servo_map.vector(robot.rest) if name == "rest" else np.zeros(len(servo_map.names))
    return servo_map.clamp(q)


def run(args: argparse.Namespace) -> int:
    robot = robot_from(args)
    sm = ServoMap(robot)
    bus = bus_from(args, robot)
    move = PoseMove(robot, pose_target(robot, args.pose, sm), max_speed=args.speed)
    posing = Run(RunSpec(robot=robot, source=move, bus=bus, options=RunOptions(
        rate_hz=args.rate, hold=True, signals=True, watch=False)))
    with posing:
        print(f"torque ON; ramping to {args.pose} (peak {args.speed:g} rad/s, "
              f"{args.rate:g} Hz)", flush=True)
        posing.stream()
    done = posing.result
    stats = done.stats
    if not stats.holding:
        print(f"stopped: {stats.stop_reason}; {torque_words(stats)}")
    elif posing.latch.first is not None:
        print(f"interrupted ({stats.stop_reason}): ramp stopped; holding the last goal, "
              "torque stays ON (`biped torque off` to release)")
    else:
        print(f"at {args.pose} pose after {stats.duration_s:.2f} s ({stats.ticks} steps); "
              "torque left ON (`biped torque off` to release)")
    return done.exit_code
