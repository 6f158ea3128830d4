"""`biped emulate`: serve an emulated servo chain on a pseudo-terminal until stopped.

Prints the pty device path (one line, flushed) so a script or another shell can point a
bus at it (``biped scan --bus dynamixel --port /dev/pts/N``); SIGINT / SIGTERM stop it.

``--factory-new N`` serves N servos as shipped (id 1, factory baud and return delay), none
plugged in: each line read on stdin plugs the next one in alone (the previous one is
unplugged), as a user connects one new servo at a time; the line ``all`` plugs in all.
The servos are the robot's bus model unless ``--model`` names another; a dual-axis model
(2XL430-W250) serves N cases, each a line plugs in whole (its two axes at ids 1 and 2).

A chain's servos move by the servo model (``sim.emulator.servo_dynamics``: the gains the
driver wrote, the supply, gearbox friction; ``--motion travel``, LX servos and factory-new
ones: at constant speed onto the goal); ``--load ID=MASS@LENGTH`` hangs a weight [kg] on
an arm [m] on servo ID (repeatable), q = 0 hanging down at the joint's zero, so a loaded
joint lags its goal as a real one does.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from types import FrameType
from typing import TYPE_CHECKING

from robot.commands.common import add_robot_args, positive_int, robot_from
from robot.errors import ConfigError
from robot.servo.bench_load import BenchLoad, parse_load

if TYPE_CHECKING:
    from sim.emulator.chain import Emulator

PROTOCOLS = ("dynamixel", "dynamixel1", "feetech", "lx")
MOTIONS = ("model", "travel")
ALIVE_CHECK_S = 0.5          # how often the emulator process is checked [s]
#: Said once when the host discards its own output (sim.emulator.server, packet mode).
FLUSH_WARNING = ("biped emulate: warning: the host flushed its output buffer (tcflush "
                 "TCOFLUSH; pyserial reset_output_buffer / flushOutput): on a pseudo-terminal "
                 "that discards the packets the kernel has not yet passed on, so some never "
                 "reach the servos (a USB adapter has sent them by then). pypot does it before "
                 "every packet: see docs/third_party.md")


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
    p.add_argument("--factory-new", type=positive_int, default=None, metavar="N",
                   help="serve N servos as shipped (id 1, factory baud); each stdin line "
                        "plugs in the next one alone, the line 'all' plugs in all")
    p.add_argument("--motion", choices=MOTIONS, default="model",
                   help="model: the servo model moves the horns (default); travel: "
                        "constant speed onto the goal")
    p.add_argument("--load", action="append", default=[], metavar="ID=MASS@LENGTH",
                   help="a weight [kg] on an arm [m] on servo ID, e.g. 3=0.5@0.1 "
                        "(repeatable; --motion model)")
    p.add_argument("--model", default=None,
                   help="servo model of the --factory-new servos, e.g. 2XL430-W250 (a "
                        "dual-axis case a servo; default: the robot config's bus model)")
    return p


def loads_from(texts: list[str]) -> dict[int, BenchLoad]:
    """``ID=MASS@LENGTH`` texts → id → load; ConfigError naming the bad one."""
    out: dict[int, BenchLoad] = {}
    for text in texts:
        sid, sep, rest = text.partition("=")
        if not sep or not sid.strip().isdigit():
            raise ConfigError(f"--load: expected ID=MASS@LENGTH (e.g. 3=0.5@0.1), got {text!r}")
        out[int(sid)] = parse_load(rest, where=f"--load {text}")
    return out


def _plug_from_stdin(emu: Emulator, count: int, stop: threading.Event) -> None:
    """Plug the next factory-new servo per stdin line; 'all' plugs every one. A
    dual-axis case is one servo here: its first axis is plugged, the emulator adds the other."""
    axes = len(emu.ids) // count
    plugged = 0
    for line in sys.stdin:
        if stop.is_set():
            return
        if line.strip().lower() == "all":
            emu.plug_all()
            print(f"plugged all {count} servos", flush=True)
        elif plugged < count:
            emu.plug(plugged * axes)
            plugged += 1
            print(f"plugged new servo {plugged} of {count}", flush=True)
        else:
            print(f"biped emulate: all {count} new servos were plugged in already; "
                  "send 'all' to connect the whole chain", file=sys.stderr, flush=True)


def _flush_warning(emu: Emulator) -> bool:
    """Say FLUSH_WARNING if the host has flushed its output; whether it was said."""
    if not emu.counters().get("host_output_flushes"):
        return False
    print(FLUSH_WARNING, file=sys.stderr, flush=True)
    return True


def run(args: argparse.Namespace) -> int:
    from sim.emulator.chain import Emulator

    if args.factory_new and args.baud:
        print("biped emulate: error: --baud: factory-new servos listen at their factory "
              "baud; drop --baud or --factory-new", file=sys.stderr)
        return 2
    if args.model and not args.factory_new:
        print("biped emulate: error: --model: only for --factory-new servos (a chain "
              "takes its models from the robot config); add --factory-new N",
              file=sys.stderr)
        return 2
    robot = robot_from(args)
    protocol = args.protocol or robot.bus.kind
    loads = loads_from(args.load)
    motion = "travel" if protocol == "lx" and not loads else args.motion   # LX: no model
    stop = threading.Event()

    def on_signal(signum: int, frame: FrameType | None) -> None:
        stop.set()

    old = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        model = args.model or (robot.bus.model if protocol == robot.bus.kind else None)
        emu = (Emulator.factory_new(protocol, args.factory_new, model=model) if args.factory_new
               else Emulator(protocol, robot, baud=args.baud, loads=loads, motion=motion))
        with emu:
            print(emu.port, flush=True)
            if args.factory_new:
                threading.Thread(target=_plug_from_stdin, args=(emu, args.factory_new, stop),
                                 daemon=True).start()
            warned = False
            while not stop.wait(ALIVE_CHECK_S):
                if not emu.alive:
                    print("biped emulate: error: the emulator process exited",
                          file=sys.stderr)
                    return 1
                warned = warned or _flush_warning(emu)
            if not warned:
                _flush_warning(emu)
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)
    return 0
