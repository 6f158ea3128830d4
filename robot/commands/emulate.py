"""`biped emulate`: serve an emulated servo chain on a pseudo-terminal until stopped.

Prints the pty device path (one line, flushed) so a script or another shell can point a
bus at it (``biped scan --bus dynamixel --port /dev/pts/N``); SIGINT / SIGTERM stop it.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from types import FrameType

from robot.commands.common import add_robot_args, positive_int, robot_from

PROTOCOLS = ("dynamixel", "feetech")
ALIVE_CHECK_S = 0.5          # how often the emulator process is checked [s]


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "emulate", help="emulate the robot's servo chain on a pty (prints the device path)",
        description="Serve an emulated Dynamixel 2.0 / Feetech STS servo chain on a "
                    "pseudo-terminal for the vendor SDKs; prints the device path, serves "
                    "until interrupted.")
    p.add_argument("--protocol", choices=PROTOCOLS, default=None,
                   help="wire protocol (default: the robot config's bus kind)")
    add_robot_args(p, gait=False)
    p.add_argument("--baud", type=positive_int, default=None,
                   help="chain baud rate [bit/s]; other rates get no answer "
                        "(default: the robot config's)")
    return p


def run(args: argparse.Namespace) -> int:
    from sim.emulator import Emulator

    robot = robot_from(args)
    protocol = args.protocol or robot.bus.kind
    stop = threading.Event()

    def on_signal(signum: int, frame: FrameType | None) -> None:
        stop.set()

    old = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        with Emulator(protocol, robot, baud=args.baud) as emu:
            print(emu.port, flush=True)
            while not stop.wait(ALIVE_CHECK_S):
                if not emu.alive:
                    print("biped emulate: error: the emulator process exited",
                          file=sys.stderr)
                    return 1
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)
    return 0
