"""The arguments of `biped identify record` (robot/commands/identify_record.py runs it)."""

from __future__ import annotations

import argparse
from pathlib import Path

from robot.commands.common import bounded_float, bounded_int, one_line_errors
from robot.config.servo_file import physics_for
from robot.errors import ConfigError
from robot.servo import log_rules
from robot.servo.bench_load import MAX_LENGTH, MAX_MASS
from robot.servo.models import MODELS

DEFAULT_KP = "400,800"


def add_record_parser(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    rec = one_line_errors(sub.add_parser(
        "record", help="record pendulum logs from a real servo on this project's bus"))
    rec.add_argument("--bus", required=True, choices=("dynamixel", "dynamixel1", "feetech"),
                     help="the servo's bus")
    rec.add_argument("--port", default=None, metavar="DEV", help="serial device")
    rec.add_argument("--id", dest="sid", required=True, type=bounded_int(0, 252, what="an id"),
                     metavar="N", help="the servo's id")
    rec.add_argument("--motor", required=True, metavar="NAME",
                     help=f"its model: {', '.join(MODELS)}")
    rec.add_argument("--mass", required=True, metavar="KG", type=float,
                     help=f"the weight on the arm [kg] (up to {MAX_MASS:g})")
    rec.add_argument("--length", required=True, metavar="M", type=float,
                     help=f"from the shaft to the weight [m] (up to {MAX_LENGTH:g})")
    rec.add_argument("--out", required=True, metavar="DIR", help="directory for the logs")
    rec.add_argument("--kp", default=DEFAULT_KP, metavar="A,B",
                     help=f"P gain register values, one set of runs each (default {DEFAULT_KP})")
    rec.add_argument("--zero", type=int, default=None, metavar="TICKS",
                     help="present position with the arm hanging down (default: mid-range)")
    rec.add_argument("--range", dest="span", default=1.6, metavar="RAD",
                     type=bounded_float(0.1, 3.0, "rad", what="a range"),
                     help="joint limits: +-RAD around the zero (default 1.6)")
    rec.add_argument("--amplitude", default=1.0, metavar="RAD",
                     type=bounded_float(0.05, 3.0, "rad", what="an amplitude"),
                     help="trajectory amplitude [rad] (default 1.0)")
    rec.add_argument("--timeout-ms", default=None, metavar="MS",
                     type=bounded_float(1.0, 1000.0, "ms", what="a reply timeout"),
                     help="reply timeout [ms] (default: the bundled robot's for --bus; "
                          "more for a USB adapter with a slow latency timer)")
    rec.add_argument("--seconds", default=6.0, metavar="S",
                     type=bounded_float(1.0, 60.0, "s", what="a duration"),
                     help="seconds per run (default 6)")


def _kps(text: str, motor: str) -> list[int]:
    """The P register values of ``--kp``, each one ``motor``'s register can hold."""
    try:
        kps = [int(x) for x in text.split(",")]
    except ValueError:
        kps = []
    if not kps:
        raise ConfigError(f"--kp: expected gain register values like {DEFAULT_KP}, got {text!r}")
    law = physics_for(motor).law if motor in MODELS else None   # an unknown one: refused later
    return [log_rules.register_value("--kp", k, law=law) for k in kps]


def run_record_command(args: argparse.Namespace) -> int:
    from robot.commands.identify_record import run_record
    from robot.run.signals import installed

    # the rules every log is read by, before a servo moves (robot/servo/log_rules.py)
    log_rules.rig("--", mass=args.mass, length=args.length)
    kps = _kps(args.kp, args.motor)
    written, stopped = run_record(args.bus, args.port, motor=args.motor, sid=args.sid,
                                  zero=args.zero, span=args.span, mass=args.mass,
                                  length=args.length, kps=kps, seconds=args.seconds,
                                  out=Path(args.out), amplitude=args.amplitude,
                                  timeout_ms=args.timeout_ms)
    for path in written:
        print(f"wrote {path}")
    if stopped is not None:
        print(f"stopped ({stopped}): torque off; {len(written)} logs complete")
        latch = installed()
        return 128 + latch.first if latch is not None and latch.first else 1
    print(f"{len(written)} logs in {args.out}; torque off")
    return 0
