"""`biped torque on|off`: enable torque holding the present position, or release it."""

from __future__ import annotations

import argparse

from robot.bus.factory import make_bus
from robot.commands.common import add_bus_args, add_robot_args, robot_from
from robot.commands.pose import hold_present
from robot.servo_map import ServoMap


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser("torque", help="enable or disable torque on every joint",
                              description=__doc__)
    p.add_argument("state", choices=("on", "off"))
    add_robot_args(p, gait=False)
    add_bus_args(p)
    return p


def run(args: argparse.Namespace) -> int:
    robot = robot_from(args)
    bus = make_bus(args.bus, robot=robot, port=args.port, baud=args.baud)
    bus.open()
    try:
        if args.state == "on":
            hold_present(bus, ServoMap(robot))
            print(f"torque ON on {len(robot.ids)} servos, holding their present position")
        else:
            bus.set_torque(robot.ids, enabled=False)
            print(f"torque OFF on {len(robot.ids)} servos: the robot is limp, support it")
    finally:
        bus.close(torque_off=False)
    return 0
