"""`biped curves`: the gait's channels and joint angles as a CSV (and a plot)."""

from __future__ import annotations

import argparse
import logging

import numpy as np

from robot.commands.common import (
    add_robot_args,
    gait_from,
    one_line_errors,
    output_file,
    rate_hz,
    robot_from,
    seconds,
    writing,
)
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.previs.curves import plot_curves, write_csv

log = logging.getLogger(__name__)

#: Most CSV rows (--seconds x --rate + 1): 1e6 rows of ~60 columns is ~1 GB of text.
MAX_ROWS = 1_000_000


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("curves", help="write the gait as CSV curves (and a PNG plot)",
                       description="Evaluate the gait at constant parameters and write the "
                                   "paper's channels and the joint angles.")
    add_robot_args(p)
    p.add_argument("--seconds", type=seconds, default=4.0, help="duration [s]")
    p.add_argument("--rate", type=rate_hz, default=100.0, help="samples per second [Hz]")
    p.add_argument("--out", required=True, type=output_file, metavar="FILE.csv",
                   help="CSV to write")
    p.add_argument("--plot", type=output_file, metavar="FILE.png", help="also write a plot")
    return one_line_errors(p)


def run(args: argparse.Namespace) -> int:
    n = int(round(args.seconds * args.rate)) + 1
    if n > MAX_ROWS:
        raise ConfigError(f"--seconds {args.seconds:g} x --rate {args.rate:g}: {n} rows; "
                          f"expected at most {MAX_ROWS}")
    robot = robot_from(args)
    gait = gait_from(args)
    times = np.arange(n) / args.rate
    engine = GaitEngine(robot, gait.for_robot(robot))
    channels, q = engine.curves(times)
    with writing("--out", args.out):
        write_csv(args.out, times, channels, robot.joint_names, q)
    print(f"wrote {args.out}: {n} rows, gait {gait.name}, robot {robot.name}")
    if args.plot:
        with writing("--plot", args.plot):
            plot_curves(args.plot, times, channels, robot.joint_names, q,
                        title=f"gait {gait.name} on {robot.name}")
        print(f"wrote {args.plot}")
    return 0
