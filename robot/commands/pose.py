"""`biped pose rest|zero`: ramp smoothly from where the robot is to a named pose, then hold.

Reads the present position, enables torque holding it (no snap to a stale goal), then
streams a minimum-jerk ramp (robot.ramp) at a fixed rate on absolute monotonic deadlines.
Torque stays ON at the end; Ctrl-C stops the ramp and holds where it is.
"""

from __future__ import annotations

import argparse
import logging

import numpy as np
import numpy.typing as npt

from robot.bus.base import Bus
from robot.bus.factory import make_bus
from robot.clock import Clock, MonotonicClock
from robot.commands.common import add_bus_args, add_robot_args, positive_float, robot_from
from robot.config import RobotConfig
from robot.ramp import ramp
from robot.servo_map import ServoMap

log = logging.getLogger(__name__)

POSES = ("rest", "zero")
#: Beyond this [rad] outside its limits, a joint's first goal (at the limit) is a visible jump.
OUTSIDE_WARN_RAD = 0.05


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser("pose", help="ramp to the rest or zero pose and hold it",
                              description=__doc__)
    p.add_argument("pose", choices=POSES, help="rest: the robot config's [rest]; zero: all 0")
    add_robot_args(p, gait=False)
    add_bus_args(p)
    p.add_argument("--rate", type=positive_float, default=50.0, help="goal rate [Hz]")
    p.add_argument("--speed", type=positive_float, default=1.0,
                   help="peak joint speed [rad/s], capped by each joint's max_speed_rad_s")
    return p


def pose_target(robot: RobotConfig, name: str, servo_map: ServoMap) -> npt.NDArray[np.float64]:
    """Joint angles [rad] of pose ``name`` (rest: missing joints 0), inside the limits."""
    q = servo_map.vector(robot.rest) if name == "rest" else np.zeros(len(servo_map.names))
    return servo_map.clamp(q)


def hold_present(bus: Bus, servo_map: ServoMap) -> npt.NDArray[np.float64]:
    """Goal := present position (clamped to the limits), then torque on. Returns it [rad]."""
    q_now = servo_map.from_positions(bus.read_positions(servo_map.ids))
    q_hold = servo_map.clamp(q_now)
    for name, a, b in zip(servo_map.names, q_now, q_hold, strict=True):
        if abs(a - b) > OUTSIDE_WARN_RAD:
            log.warning("%s is at %.3f rad, outside its limits: it will move to %.3f rad",
                        name, a, b)
    bus.write_goals(servo_map.goals(q_hold.tolist()))
    bus.set_torque(servo_map.ids, enabled=True)
    return q_hold


def stream(bus: Bus, servo_map: ServoMap, path: npt.NDArray[np.float64], rate_hz: float, *,
           clock: Clock | None = None) -> int:
    """Write ``path[1:]`` at ``rate_hz`` on absolute deadlines; returns rows written.

    clock: default the bus's own ``clock`` if it has one (simulation time), else monotonic.
    When late by more than a period the schedule is shifted rather than caught up with a
    burst of goals (a burst would exceed the slew limit in real time).
    """
    clock = clock or getattr(bus, "clock", None) or MonotonicClock()
    period = 1.0 / rate_hz
    t0 = clock.now()
    for k in range(1, len(path)):
        deadline = t0 + k * period
        lag = clock.now() - deadline
        if lag > period:
            t0 += lag
        else:
            clock.sleep_until(deadline)
        bus.write_goals(servo_map.goals(path[k].tolist()))
    return len(path) - 1


def run(args: argparse.Namespace) -> int:
    robot = robot_from(args)
    sm = ServoMap(robot)
    bus = make_bus(args.bus, robot=robot, port=args.port, baud=args.baud)
    bus.open()
    try:
        q_start = hold_present(bus, sm)
        path = ramp(q_start, pose_target(robot, args.pose, sm),
                    np.minimum(sm.max_speed, args.speed), args.rate)
        print(f"torque ON; ramping to {args.pose} over {(len(path) - 1) / args.rate:.2f} s "
              f"({len(path) - 1} steps at {args.rate:g} Hz)")
        try:
            stream(bus, sm, path, args.rate)
        except KeyboardInterrupt:
            print("interrupted: ramp stopped; holding the last goal, torque stays ON")
            return 130
        print(f"at {args.pose} pose; torque left ON (`biped torque off` to release)")
        return 0
    finally:
        bus.close(torque_off=False)
