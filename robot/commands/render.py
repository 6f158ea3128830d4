"""`biped render`: a previs clip (mp4 or gif) of a gait walked in MuJoCo, filmed by the
tracking camera."""

from __future__ import annotations

import argparse
import logging

from robot.commands.common import (
    add_robot_args,
    add_set_arg,
    params_from,
    positive_float,
    positive_int,
    robot_from,
)

log = logging.getLogger(__name__)


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("render", help="render a walk to a video clip (mp4 or gif)",
                       description="Walk the gait on the MuJoCo bus and film it with the "
                                   "tracking camera (offscreen, MUJOCO_GL=egl).")
    add_robot_args(p)
    p.add_argument("--seconds", type=positive_float, default=5.0, help="clip length [s]")
    p.add_argument("--out", required=True, metavar="FILE.mp4|FILE.gif", help="clip to write")
    p.add_argument("--width", type=positive_int, default=640, help="frame width [px]")
    p.add_argument("--height", type=positive_int, default=360, help="frame height [px]")
    p.add_argument("--fps", type=positive_float, default=30.0, help="video frames per second")
    p.add_argument("--rate", type=positive_float, default=200.0, help="control rate [Hz]")
    p.add_argument("--camera", default="track", help="MuJoCo camera (default: %(default)s)")
    add_set_arg(p)
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    return p


def run(args: argparse.Namespace) -> int:
    from sim.render import ClipSpec, check_output, render_walk

    spec = ClipSpec(seconds=args.seconds, width=args.width, height=args.height, fps=args.fps,
                    rate_hz=args.rate, camera=args.camera)
    check_output(args.out, spec)
    robot = robot_from(args)
    gait, params = params_from(args)
    result = render_walk(robot, params, args.out, spec=spec, progress=not args.quiet)
    fell = ", the robot FELL" if result.fell else ""
    print(f"wrote {result.path}: {result.frames} frames, {result.seconds:.2f} s at "
          f"{args.fps:g} fps, {args.width}x{args.height}, gait {gait.name}{fell}")
    return 0
