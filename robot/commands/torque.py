"""`biped torque on|off`: enable torque holding the present position, or release it.

`on` runs the streamer's start (a ``PoseMove`` to the present pose): it refuses, with
torque untouched, if a joint is outside its limits, sets goal := present, then torque on.
"""

from __future__ import annotations

import argparse

from robot.bus.base import bus_rate
from robot.bus.servo_map import ServoMap
from robot.commands.common import (
    add_bus_args,
    add_robot_args,
    bus_from,
    one_line_errors,
    robot_from,
)
from robot.loop.streamer import Streamer
from robot.motion.posing import PoseMove
from robot.run.result import torque_words
from robot.run.session import bus_session


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "torque", help="enable or disable torque on every joint",
        description="Turn torque on, holding the present position (on), or release every "
                    "joint (off). 'on' refuses, with torque untouched, if a joint is outside "
                    "its limits; otherwise each servo's goal becomes its present position "
                    "before torque comes on, so nothing moves.")
    p.add_argument("state", choices=("on", "off"))
    add_robot_args(p, gait=False)
    add_bus_args(p)
    return one_line_errors(p)


def run(args: argparse.Namespace) -> int:
    robot = robot_from(args)
    bus = bus_from(args, robot)
    with bus_session(bus, torque_off=args.state == "off"):
        if args.state == "off":
            bus.set_torque(robot.ids, enabled=False)
            print(f"torque OFF on {len(robot.ids)} servos: the robot is limp, support it")
            return 0
        sm = ServoMap(robot)
        here = PoseMove(robot, sm.from_positions(bus.read_positions(sm.ids)))
        stats = Streamer(sm, bus, here, rate_hz=bus_rate(bus), hold_at_end=True).run()
    if stats.fault or not stats.holding:
        print(f"stopped: {stats.stop_reason}; {torque_words(stats)}")
        return 1
    print(f"torque ON on {len(robot.ids)} servos, holding their present position")
    return 0
