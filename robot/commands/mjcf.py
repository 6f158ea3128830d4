"""`biped mjcf --out DIR`: write the robot's MJCF (robot.xml + scene.xml) for MuJoCo tools.

Open the result with ``python -m mujoco.viewer --mjcf DIR/scene.xml``.
"""

from __future__ import annotations

import argparse

from robot.commands.common import (
    add_robot_args,
    bounded_float,
    checked,
    one_line_errors,
    output_dir,
    robot_from,
)


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser("mjcf", help="write the robot as MuJoCo MJCF (robot + scene)",
                              description=__doc__,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
    add_robot_args(p, gait=False)
    p.add_argument("--out", required=True, metavar="DIR",
                   help="output directory (created if missing)")
    # sim.mujoco.mjcf accepts (0, 0.01] s: coarser steps make the contacts unstable.
    p.add_argument("--timestep", type=bounded_float(0.0, 0.01, "s", what="a timestep",
                                                    lo_open=True),
                   default=None, metavar="S", help="physics timestep [s] (default: 0.002)")
    return one_line_errors(p)


def run(args: argparse.Namespace) -> int:
    from sim.mujoco.mjcf import build_mjcf

    checked("--out", output_dir, args.out)  # before any work (returns 2, not argparse's exit)
    robot = robot_from(args)
    mjcf = build_mjcf(robot, timestep=args.timestep)
    mjcf.model()  # fail here, not in the user's viewer, if it does not compile
    robot_path, scene_path = mjcf.write(args.out)
    print(f"wrote {robot_path} and {scene_path} ({robot.name}); "
          f"view: python -m mujoco.viewer --mjcf {scene_path}")
    return 0
