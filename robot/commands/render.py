"""`biped render`: a previs clip (mp4 or gif) of a gait walked in MuJoCo, filmed by the
tracking camera."""

from __future__ import annotations

import argparse
import logging

from robot.commands.common import (
    add_robot_args,
    add_set_arg,
    bounded_float,
    bounded_int,
    one_line_errors,
    output_file,
    params_from,
    rate_hz,
    robot_from,
    writing,
)
from robot.errors import ConfigError

log = logging.getLogger(__name__)

#: A previs clip lasts at most an hour.
clip_seconds = bounded_float(0.0, 3600.0, "s", what="a clip length", lo_open=True)
#: Frame sizes parse up to this; sim.mujoco.render.check_output enforces the real limits.
frame_px = bounded_int(1, 100_000, "px", what="a frame size")
#: A GIF is assembled in memory: at most this many bytes of RGB frames.
MAX_GIF_BYTES = 1 << 30


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("render", help="render a walk to a video clip (mp4 or gif)",
                       description="Walk the gait on the MuJoCo bus and film it with the "
                                   "tracking camera (offscreen, MUJOCO_GL=egl).")
    add_robot_args(p)
    p.add_argument("--seconds", type=clip_seconds, default=5.0, help="clip length [s]")
    p.add_argument("--out", required=True, type=output_file, metavar="FILE.mp4|FILE.gif",
                   help="clip to write")
    # The offscreen buffer's limits (16..1920 x 16..1080) are checked by check_output.
    p.add_argument("--width", type=frame_px, default=640, help="frame width [px]")
    p.add_argument("--height", type=frame_px, default=360, help="frame height [px]")
    p.add_argument("--fps", type=bounded_float(1.0, 120.0, "frames/s", what="a frame rate"),
                   default=30.0, help="video frames per second")
    p.add_argument("--rate", type=rate_hz, default=200.0, help="control rate [Hz]")
    p.add_argument("--camera", default="track", help="MuJoCo camera (default: %(default)s)")
    add_set_arg(p)
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    return one_line_errors(p)


def run(args: argparse.Namespace) -> int:
    from sim.mujoco.render import ClipSpec, check_output, render_walk

    spec = ClipSpec(seconds=args.seconds, width=args.width, height=args.height, fps=args.fps,
                    rate_hz=args.rate, camera=args.camera)
    path = check_output(args.out, spec)
    size = spec.frames * spec.width * spec.height * 3
    if path.suffix.lower() == ".gif" and size > MAX_GIF_BYTES:
        raise ConfigError(f"--seconds/--fps/--width/--height: a GIF of {spec.frames} frames "
                          f"of {spec.width}x{spec.height} needs {size / 2**30:.1f} GiB in "
                          f"memory; expected at most {MAX_GIF_BYTES / 2**30:g} GiB (shorter, "
                          "smaller, or .mp4)")
    robot = robot_from(args)
    gait, params = params_from(args)
    with writing("--out", args.out):
        result = render_walk(robot, params, args.out, spec=spec, progress=not args.quiet)
    fell = ", the robot FELL" if result.fell else ""
    print(f"wrote {result.path}: {result.frames} frames, {result.seconds:.2f} s at "
          f"{args.fps:g} fps, {args.width}x{args.height}, gait {gait.name}{fell}")
    return 0
