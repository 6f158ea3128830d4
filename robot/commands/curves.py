"""`biped curves`: the gait's channels and joint angles as a CSV (and a plot).

An imported robot (`biped robots import`) can add its joints in its model's own terms:
``--model-angles`` adds one column per joint, named as the model file names it, in the
file's convention (robot/config/model_angles.py: what MuJoCo's qpos takes); ``--targets``
adds the sole targets the IK solved for, in the model's root link frame
(``r_sole_x, r_sole_y, r_sole_z, l_sole_x, l_sole_y, l_sole_z`` [m]), so the IK can be
checked with the model file and the CSV alone."""

from __future__ import annotations

import argparse
import logging

import numpy as np
import numpy.typing as npt

from robot.commands.common import (
    add_robot_args,
    gait_from,
    one_line_errors,
    output_file,
    plot_output,
    rate_hz,
    robot_from,
    seconds,
    writing,
)
from robot.config.model_angles import ModelAngles
from robot.config.robot import RobotConfig
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
    p.add_argument("--plot", type=plot_output, metavar="FILE.png", help="also write a plot")
    p.add_argument("--model-angles", action="store_true",
                   help="an imported robot: add each joint under its model's name, in the "
                        "model's convention [rad]")
    p.add_argument("--targets", action="store_true",
                   help="an imported robot: add the sole targets in the model's root link "
                        "frame [m]")
    return one_line_errors(p)


def model_columns(robot: RobotConfig, engine: GaitEngine, times: npt.NDArray[np.float64],
                  q: npt.NDArray[np.float64], *, angles: bool, targets: bool
                  ) -> dict[str, npt.NDArray[np.float64]]:
    """The --model-angles and --targets columns by name (ConfigError for a robot without
    a model)."""
    out: dict[str, npt.NDArray[np.float64]] = {}
    if angles:
        out.update(ModelAngles.of(robot, what="--model-angles").named(q.T))
    if targets:
        ModelAngles.of(robot, what="--targets")
        assert robot.body is not None
        soles = robot.body.pelvis_to_root(engine.sole_targets(times))
        for side, sole in zip("rl", soles, strict=True):
            out.update({f"{side}_sole_{a}": sole[:, k] for k, a in enumerate("xyz")})
    return out


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
    extra = model_columns(robot, engine, times, q, angles=args.model_angles,
                          targets=args.targets)
    with writing("--out", args.out):
        try:
            write_csv(args.out, times, channels, robot.joint_names, q, extra=extra)
        except ValueError as e:
            raise ConfigError(f"--model-angles: {robot.source}: the model's joint names a "
                              f"column of the curves file ({e}); rename it in the model "
                              "and import again") from None
    print(f"wrote {args.out}: {n} rows, gait {gait.name}, robot {robot.name}")
    if args.plot:
        with writing("--plot", args.plot):
            plot_curves(args.plot, times, channels, robot.joint_names, q,
                        title=f"gait {gait.name} on {robot.name}")
        print(f"wrote {args.plot}")
    return 0
