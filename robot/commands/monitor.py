"""`biped monitor`: torque off, then a live table of every joint read back from the servos.

Move the joints by hand to check the calibration: angle in rad and degrees, ticks,
temperature, load, hardware-error flags and the joint's limits (marked when outside).
Torque is turned off on start and no goal is ever written. The table refreshes in place
(on a terminal) on absolute deadlines at ``--rate``; a failed read shows as a line and the
next refresh tries again. ``--once``: one table, then exit. ``--json``: one JSON object per
refresh. Ctrl-C (SIGINT) exits 130, SIGTERM 143, torque still off.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Mapping
from typing import Any

from robot.bus.base import Bus
from robot.bus.servo_map import ServoMap
from robot.commands.common import (
    HARDWARE_BUSES,
    add_bus_args,
    add_robot_args,
    bounded_float,
    bus_from,
    one_line_errors,
    robot_from,
)
from robot.config.robot import RobotConfig
from robot.errors import BusError
from robot.run.signals import SignalLatch, stop_on_signals
from robot.setup.monitor_table import format_table, rows

#: --rate: a terminal table faster than 50 Hz is unreadable; slower than 0.1 Hz is not live.
monitor_rate = bounded_float(0.1, 50.0, "Hz", what="a rate")
CLEAR_BELOW = "\x1b[J"


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser("monitor", help="torque off; live table of joint angles, "
                              "temperatures, loads and errors", description=__doc__)
    add_robot_args(p, gait=False)
    add_bus_args(p, choices=HARDWARE_BUSES)
    p.add_argument("--rate", type=monitor_rate, default=5.0,
                   help="refreshes per second (default: %(default)s)")
    p.add_argument("--once", action="store_true", help="print one table and exit")
    p.add_argument("--json", action="store_true", help="one JSON object per refresh")
    return one_line_errors(p)


def next_deadline(start: float, period: float, now: float) -> float:
    """The first ``start + k * period`` (k = 1, 2, ...) after ``now``: refreshes stay on
    the grid, and a slow read skips the deadlines it missed instead of bunching up."""
    k = max(1, int((now - start) // period) + 1)
    return start + k * period


class _Stop:
    """A SignalLatch target: any signal ends the loop at its next check."""

    def __init__(self) -> None:
        self.stop = False

    def request_stop(self, reason: str = "") -> None:
        self.stop = True

    def emergency_stop(self, reason: str = "") -> None:
        self.stop = True


class _Screen:
    """Prints frames; on a terminal each frame overwrites the previous one."""

    def __init__(self, *, in_place: bool) -> None:
        self.in_place = in_place
        self.lines = 0

    def show(self, lines: list[str]) -> None:
        if self.in_place and self.lines:
            sys.stdout.write(f"\x1b[{self.lines}F{CLEAR_BELOW}")
        elif self.lines:
            sys.stdout.write("\n")
        sys.stdout.write("\n".join(lines) + "\n")
        sys.stdout.flush()
        self.lines = len(lines)


def _frame(robot: RobotConfig, sm: ServoMap, bus: Bus, *, t: float, title: str,
           as_json: bool, strict: bool,
           gains: Mapping[int, Mapping[str, int] | None] | None = None) -> list[str]:
    """One refresh as output lines; a BusError becomes an error line unless ``strict``."""
    try:
        table = rows(robot, sm, bus.read_state(sm.ids), gains=gains)
    except BusError as e:
        if strict:
            raise
        if as_json:
            return [json.dumps({"t": round(t, 3), "error": str(e)})]
        return [title, f"read failed: {e}; retrying"]
    if as_json:
        obj: dict[str, Any] = {"t": round(t, 3), "torque": "off",
                               "joints": [r.as_dict() for r in table]}
        return [json.dumps(obj)]
    return format_table(table, title=title)


def run(args: argparse.Namespace) -> int:
    robot = robot_from(args)
    sm = ServoMap(robot)
    bus = bus_from(args, robot)
    port = args.port or robot.bus.port
    latch, stopper = SignalLatch(), _Stop()
    with stop_on_signals(stopper, latch):  # a signal never lands inside a transaction
        bus.open()
        try:
            bus.set_torque(sm.ids, enabled=False)
            gains = {sid: bus.read_gains(sid) for sid in sm.ids}   # read once: they hold
            if args.once:
                title = f"{robot.name} on {bus.kind} {port}: torque OFF"
                for line in _frame(robot, sm, bus, t=0.0, title=title, as_json=args.json,
                                   strict=True, gains=gains):
                    print(line)
            else:
                _loop(robot, sm, bus, args, port, stopper, gains)
        finally:
            bus.close(torque_off=True)  # torque off once more (writes torque_enable only)
    if not (args.json or args.once):
        print(f"biped monitor: stopped; torque off on {len(sm.ids)} servos")
    return latch.exit_code(None)  # 0, or 128 + the signal that ended it


def _loop(robot: RobotConfig, sm: ServoMap, bus: Bus, args: argparse.Namespace, port: str,
          stopper: _Stop, gains: Mapping[int, Mapping[str, int] | None]) -> None:
    screen = _Screen(in_place=sys.stdout.isatty() and not args.json)
    period = 1.0 / args.rate
    start = deadline = time.monotonic()
    while not stopper.stop:
        t = time.monotonic() - start
        title = (f"{robot.name} on {bus.kind} {port}: torque OFF, move the joints by hand "
                 f"(Ctrl-C to exit)  t={t:.1f} s")
        lines = _frame(robot, sm, bus, t=t, title=title, as_json=args.json, strict=False,
                       gains=gains)
        if args.json:
            print(lines[0], flush=True)
        else:
            screen.show(lines)
        deadline = next_deadline(start, period, max(deadline, time.monotonic()))
        while not stopper.stop and (left := deadline - time.monotonic()) > 0:
            time.sleep(min(left, 0.05))  # short naps: a signal ends the wait quickly
