"""`biped export`: the motion as BVH or glTF for Blender, Maya or any previs tool.

``--gait NAME --seconds S``: the gait at constant parameters (the paper's steady cycle,
evaluated directly, no ramp), ``--take FILE``: a recorded take's joint stream (as it went
to the servos, ramps and rest included). The format follows ``--out``: ``.bvh``, or
``.glb`` / ``.gltf`` (a skinned glTF 2.0 animation, metres). Skeleton, axes and units:
robot/previs/bvh.py and robot/previs/gltf.py.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from robot.commands.common import (
    add_robot_args,
    bounded_float,
    checked,
    gait_from,
    input_file,
    one_line_errors,
    output_file,
    robot_from,
    seconds,
    writing,
)
from robot.config.bundled import DEFAULT_ROBOT_NAME
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.motion.takes import SUFFIX, is_take, read_take
from robot.previs.bvh import UNITS, resample, write_bvh
from robot.previs.gltf import SUFFIXES as GLTF_SUFFIXES
from robot.previs.gltf import write_gltf

#: Most frames written (an hour at 60 fps).
MAX_FRAMES = 216_000


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("export", help="write the gait or a take as BVH or glTF (previs)",
                       description=__doc__.split("\n\n")[0])
    add_robot_args(p)
    p.add_argument("--take", default=None, metavar=f"FILE{SUFFIX}",
                   help="export a recorded take instead of the gait")
    p.add_argument("--seconds", type=seconds, default=10.0, help="gait duration [s]")
    p.add_argument("--fps", type=bounded_float(1.0, 240.0, "frame/s", what="a frame rate"),
                   default=30.0, help="frames per second (default: %(default)s)")
    p.add_argument("--units", choices=sorted(UNITS), default=None,
                   help="length unit of a BVH skeleton (default: cm; glTF is always m)")
    p.add_argument("--out", required=True, type=output_file, metavar="FILE.bvh|.glb|.gltf")
    return one_line_errors(p)


def run(args: argparse.Namespace) -> int:
    suffix = Path(args.out).suffix
    if suffix not in (".bvh", *GLTF_SUFFIXES):
        raise ConfigError(f"--out {args.out}: expected a .bvh, .glb or .gltf file")
    if suffix != ".bvh" and args.units not in (None, "m"):
        raise ConfigError(f"--units {args.units}: glTF lengths are metres; leave --units out "
                          f"for {args.out}")
    if args.take:
        checked("--take", input_file, args.take)
        if not is_take(args.take):
            raise ConfigError(f"--take {args.take}: expected a take (NAME{SUFFIX})")
        take = read_take(args.take)
        own = take.header.robot_file if Path(take.header.robot_file).is_file() \
            else take.header.robot
        robot = load_robot(own if args.robot == DEFAULT_ROBOT_NAME else args.robot)
        if robot.joint_names != take.header.joints:
            raise ConfigError(f"--take {args.take}: recorded on {take.header.robot}, not "
                              f"{robot.name}")
        if len(take.t) < 2:
            raise ConfigError(f"--take {args.take}: fewer than two ticks recorded")
        t = np.arange(len(take.t)) / take.header.rate_hz
        q = resample(t, take.q, args.fps)
        what, label = f"take {args.take}", Path(args.take).name.removesuffix(SUFFIX)
    else:
        n = int(round(args.seconds * args.fps)) + 1
        if n > MAX_FRAMES:
            raise ConfigError(f"--seconds {args.seconds:g} x --fps {args.fps:g}: {n} frames; "
                              f"expected at most {MAX_FRAMES}")
        robot = robot_from(args)
        gait = gait_from(args)
        _, qt = GaitEngine(robot, gait.for_robot(robot)).curves(np.arange(n) / args.fps,
                                                      with_channels=False)
        q = qt.T
        what, label = f"gait {gait.name}", gait.name
    with writing("--out", args.out):
        if suffix == ".bvh":
            units = args.units or "cm"
            frames = write_bvh(args.out, robot, q, 1.0 / args.fps, units=units)
        else:
            units = "m"
            frames = write_gltf(args.out, robot, q, 1.0 / args.fps, name=label)
    print(f"wrote {args.out}: {frames} frames at {args.fps:g} fps of {what} on {robot.name} "
          f"({units})")
    return 0
