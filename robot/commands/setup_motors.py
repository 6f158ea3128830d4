"""`biped setup-motors`: give each factory-new servo its joint's id and the robot's baud.

Connect one servo at a time (alone on the bus). For each joint it is found at any id and
any standard baud of the family, given the joint's id, the robot's baud rate and return
delay 0 (torque off; EEPROM), and checked at the new baud. ``--joint NAME --yes`` does one
joint without prompts. Refuses, with one line and nothing written, when more than one
servo answers or the servo is not the robot's model. A servo that answers as another
joint's id at the robot's baud was set up earlier (left on the chain, or the new servo's
reply was lost): it is taken only when the user says so at a prompt; ``--yes`` refuses.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable

from robot.bus.dynamixel.protocol1 import Dynamixel1Bus
from robot.bus.dynamixel.protocol2 import DynamixelBus
from robot.bus.feetech.bus import FeetechBus
from robot.bus.lx.bus import LxBus
from robot.bus.sdk.bus import SdkBus
from robot.commands.common import HARDWARE_BUSES, add_robot_args, one_line_errors, robot_from
from robot.config.robot import JointConfig, RobotConfig
from robot.errors import ConfigError
from robot.run.session import bus_session
from robot.run.signals import shield
from robot.servo.models import factory_baud
from robot.setup.dual_setup import assign_case
from robot.setup.motor_setup import (
    SetupRefused,
    answered,
    assign,
    check_model,
    find_servos,
    joints_to_set,
    set_up_already,
)

Ask = Callable[[str], str]


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser("setup-motors", help="give new servos their joint ids and baud",
                              description=__doc__)
    add_robot_args(p, gait=False)
    p.add_argument("--bus", choices=HARDWARE_BUSES, default=None,
                   help="servo bus (default: the robot's)")
    p.add_argument("--port", default=None, metavar="DEV", help="serial device (default: config)")
    p.add_argument("--joint", default=None, metavar="NAME",
                   help="set up only this joint's servo (default: every joint, one by one)")
    p.add_argument("--yes", action="store_true",
                   help="no prompt: the servo is already connected (needs --joint)")
    return one_line_errors(p)


def _bus(args: argparse.Namespace, robot: RobotConfig) -> SdkBus | LxBus:
    kind = args.bus or robot.bus.kind
    if kind != robot.bus.kind:
        raise ConfigError(f"--bus {kind}: robot {robot.name} ({robot.source}) has "
                          f"{robot.bus.kind} servos; use --bus {robot.bus.kind}")
    if kind == "lx":      # one rate; ping reports the robot file's model (none on the wire)
        return LxBus(args.port or robot.bus.port, retries=robot.bus.retries,
                     timeout_ms=robot.bus.timeout_ms, model=robot.bus.model,
                     check_health=False)
    cls: type[SdkBus] = {"dynamixel": DynamixelBus, "dynamixel1": Dynamixel1Bus}.get(
        kind, FeetechBus)
    # No robot on the bus: a servo at id 1 is a new servo, not joint 1 (and no health check);
    # the robot's servo model says which table (the XL-320's, an SCS's) and the first baud.
    servo = robot.bus.servo
    return cls(args.port or robot.bus.port, baud=factory_baud(servo), family=servo.family,
               retries=robot.bus.retries, timeout_ms=robot.bus.timeout_ms, check_health=False)


def _set_up(bus: SdkBus | LxBus, robot: RobotConfig, case: tuple[JointConfig, ...], *,
            ask: Ask | None) -> bool:
    """Find the servo (a dual-axis case: both axes) connected alone, check its model, give
    it its joint's id (ids), the robot's baud and return delay 0. A servo set up earlier
    for another joint is taken only if ``ask`` (None: ``--yes``, refused) gets a yes;
    False when the user said no (nothing written)."""
    found = find_servos(bus, robot, len(case), progress=lambda m: print(f"  {m}", flush=True))
    for f, joint in zip(sorted(found, key=lambda f: f.id), case, strict=True):
        note = check_model(f, robot, joint)
        if note:
            print(f"  note: {note}")
    where = ", ".join(f"id {f.id}" for f in sorted(found, key=lambda f: f.id))
    print(f"  found: {robot.servo(case[0]).name} at {where}, {found[0].baud} baud")
    taken = set_up_already(found, robot, case)
    if taken:
        names = " and ".join(j.name for j in case)
        whose = ", ".join(f"id {f.id} is {j.name}'s" for f, j in taken)
        seen = (f"the servo found answers at the robot's baud as another joint's id ({whose}):"
                " it looks set up already")
        if ask is None:
            raise SetupRefused(f"{seen}; nothing was written: connect only the servo for "
                               f"{names}, or run without --yes to be asked")
        if ask(f"  {seen}. Give it to {names}? [y/N] ").strip().lower() not in ("y", "yes"):
            print("  not given: nothing was written")
            return False
    with shield():           # id, baud, return delay: all of them or a signal waits
        changes = (assign(bus, found[0], case[0], robot) if len(case) == 1 else
                   assign_case(bus, found, case, robot))
    done = "; ".join(changes) if changes else "already set, nothing changed"
    ids = ", ".join(f"{j.name}: id {j.servo_id}" for j in case)
    print(f"{ids} at {robot.bus.baud} baud, checked ({done})")
    return True


def run(args: argparse.Namespace, *, ask: Ask = input) -> int:
    robot = robot_from(args)
    if args.yes and not args.joint:
        raise ConfigError("--yes needs --joint NAME: the servos are set up one at a time, "
                          "each connected alone")
    joints = joints_to_set(robot, args.joint)
    ask = answered(ask, "the servos set up so far keep their new id")
    bus = _bus(args, robot)
    print(f"setting up {len(joints)} {robot.bus.model} servo(s) of {robot.name} on "
          f"{bus.port_name}: ids from the robot file, {robot.bus.baud} baud, return delay 0 "
          "(a servo waits that long before every reply: latency in each control tick)")
    done: set[str] = set()
    with bus_session(bus, torque_off=False):
        for joint in joints:
            case = robot.case_of(joint)     # a dual-axis servo: both joints of its case
            if joint.name in done:
                continue
            done.update(j.name for j in case)
            what = (f"the servo for {joint.name} (id {joint.servo_id})" if len(case) == 1
                    else f"the {robot.servo(joint).name} case of "
                    f"{' and '.join(j.name for j in case)} "
                    f"(ids {' and '.join(str(j.servo_id) for j in case)})")
            if not args.yes:
                reply = ask(f"connect only {what} and press Enter (q to stop) ")
                if reply.strip().lower() == "q":
                    print("stopped")
                    return 1
            if not _set_up(bus, robot, case, ask=None if args.yes else ask):
                print("stopped")
                return 1
    if not args.joint:
        print(f"done: connect the chain and check with `biped scan --robot {args.robot} "
              f"--bus {robot.bus.kind} --port {bus.port_name}`")
    return 0
