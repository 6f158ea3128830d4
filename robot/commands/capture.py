"""`biped capture`: pose the robot by hand and capture keyframes to a sequence file.

The chosen limb goes limp (torque off) while every other joint holds where it is (the
streamer's start: refused if a joint is outside its limits, no snap); ``--limb all``
releases everything. Move the limb, press Enter to capture its present pose; type
``q`` (or end the input) to finish. The sequence (keyframes ``--every`` seconds apart;
edit the times by hand later) is validated like any sequence file before it is written.
At the end every servo's torque is off: support the robot.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from robot.bus.base import Bus
from robot.commands.common import (
    add_bus_args,
    add_robot_args,
    bounded_float,
    bus_from,
    one_line_errors,
    output_file,
    robot_from,
    writing,
)
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.files.atomic import write_text
from robot.motion.keyframes import SUFFIXES, load_sequence, sequence_to_toml
from robot.motion.posing import Capture, limb_joints
from robot.run.release import release
from robot.run.session import bus_session

Ask = Callable[[str], str]


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("capture", help="pose a limb by hand (torque off) and capture "
                       "keyframes", description=__doc__.split("\n\n")[0])
    add_robot_args(p, gait=False)
    add_bus_args(p)
    p.add_argument("--limb", default="arms", help="what goes limp: all, arms, right_arm, "
                   "left_arm, legs, extras (default: %(default)s)")
    p.add_argument("--every", type=bounded_float(0.05, 60.0, "s", what="a time step"),
                   default=1.0, help="time between keyframes [s] (default: %(default)s)")
    p.add_argument("--name", default=None, help="sequence name (default: the file's)")
    p.add_argument("--out", required=True, type=output_file, metavar="FILE.toml",
                   help="sequence to write (.toml)")
    return one_line_errors(p)


def run(args: argparse.Namespace, *, ask: Ask = input) -> int:
    out = Path(args.out)
    if out.suffix != ".toml":
        raise ConfigError(f"--out {args.out}: a sequence is written as .toml (read: "
                          f"{', '.join(SUFFIXES)})")
    robot = robot_from(args)
    joints = limb_joints(robot, args.limb)
    bus = bus_from(args, robot)
    capture = Capture(robot, joints)
    with bus_session(bus, torque_off=True, closed=lambda: print(
            "torque OFF on every servo: support the robot")):
        _pose_by_hand(robot, bus, capture, args, ask)
    if not capture.times:
        raise ConfigError("no keyframe captured; nothing was written")
    seq = capture.sequence(args.name or out.stem)
    with writing("--out", out):
        write_text(out, sequence_to_toml(seq))
    try:
        load_sequence(out, robot)  # as `biped play` and `walk --keyframes` will read it
    except ConfigError as e:
        raise ConfigError(f"{e} (written anyway, edit it: {out})") from None
    print(f"wrote {out}: {len(seq.times)} keyframes over {seq.duration:g} s; play it with "
          f"`biped play {out}` or layer it with `biped walk --keyframes {out}`")
    return 0


def _pose_by_hand(robot: RobotConfig, bus: Bus, capture: Capture, args: argparse.Namespace,
                  ask: Ask) -> None:
    """Release the limb, then capture a keyframe at each Enter until q or the input ends."""
    joints = release(robot, bus, args.limb)
    print(f"{args.limb}: torque OFF on {len(joints)} joints ({', '.join(joints)}); the "
          "rest holds. Move it by hand.")
    while True:
        try:
            answer = ask(f"keyframe {len(capture.times)}: Enter captures, q finishes ")
        except EOFError:
            break
        if answer.strip().lower() in ("q", "quit", "done"):
            break
        pose = capture.add(bus, step_s=args.every)
        print(f"  t = {capture.times[-1]:g} s: " + ", ".join(
            f"{j} {v:+.3f}" for j, v in zip(joints, pose, strict=True)))
