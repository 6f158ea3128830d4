"""`biped torque on|off`: enable torque holding the present position, or release it."""

from __future__ import annotations

import argparse

from robot.bus.factory import make_bus
from robot.commands.common import add_bus_args, add_robot_args, robot_from
from robot.servo_map import ServoMap
from robot.streamer import check_inside_limits

#: How far outside its limits [rad] a joint may be and still be held where it is (clamped).
HOLD_TOLERANCE_RAD = 0.02


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
            sm = ServoMap(robot)
            q = sm.from_positions(bus.read_positions(sm.ids))
            q = check_inside_limits(sm, q, tolerance=HOLD_TOLERANCE_RAD, source=robot.source)
            bus.write_goals(sm.goals(q.tolist()))   # goal := present: no snap at torque-on
            bus.set_torque(sm.ids, enabled=True)
            print(f"torque ON on {len(robot.ids)} servos, holding their present position")
        else:
            bus.set_torque(robot.ids, enabled=False)
            print(f"torque OFF on {len(robot.ids)} servos: the robot is limp, support it")
    finally:
        bus.close(torque_off=False)
    return 0
