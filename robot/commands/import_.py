"""`biped import ANIM --out NAME.take.jsonl`: retarget an animation (BVH, or glTF .glb /
.gltf; ours or Blender's) onto a robot's joints as a take that `biped play` streams.

Bones map to joints by name (the skeleton `biped export` writes), or through ``--map
MAP.toml`` (bone, axis, sign, offset per joint: robot/previs/bone_map.py). Every joint-limit,
speed and acceleration violation is listed with its time and joint, then clamped
(``--strict``: refused, exit 2, nothing written). Where the animation walks (feet planted
in turn while the root travels: robot/previs/walk_spans.py), the root's motion becomes the
gait's travel: the take's timeline has the gait walk the legs there with speed, turn and
side step from the root's (robot/previs/travel.py; ``--no-root-travel``: the legs play as
authored everywhere). ``--audio`` names the soundtrack in the take (robot/motion/show.py).
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np

from robot.commands.common import (
    add_robot_args,
    audio_offset,
    bounded_float,
    checked,
    input_file,
    output_file,
    params_from,
    robot_from,
)
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.motion.show import Show
from robot.motion.takes import SUFFIX, is_take
from robot.previs.bone_map import by_name, load_map
from robot.previs.cues import gltf_cues, sidecar_cues
from robot.previs.importing import SUFFIXES, import_animation, write_stream_take
from robot.previs.rig import UPS
from robot.previs.travel import Efficiency, efficiency_for

#: Violations listed in full; the rest are counted.
SHOWN = 40


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("import", help="retarget a BVH or glTF animation onto the robot as a "
                                      "take", description=__doc__.split("\n\n")[0])
    p.add_argument("file", metavar="ANIM", help="animation: .bvh, .glb or .gltf")
    add_robot_args(p)
    p.add_argument("--out", required=True, metavar=f"NAME{SUFFIX}", help="the take to write")
    p.add_argument("--map", default=None, metavar="MAP.toml",
                   help="bone → joint mapping for a character rigged elsewhere (default: "
                        "bones named as `biped export` names them)")
    p.add_argument("--up", choices=sorted(UPS), default=None,
                   help="the rig's up axis (default: found from the rest pose)")
    p.add_argument("--strict", action="store_true",
                   help="refuse the import (exit 2) on any violation instead of clamping")
    p.add_argument("--rate", type=bounded_float(20.0, 1000.0, "Hz", what="a rate"),
                   default=200.0, help="lowest control rate of the take [Hz]; the take runs "
                   "at a whole multiple of the animation's frame rate (default: %(default)s)")
    p.add_argument("--max-accel", type=bounded_float(1.0, 1e5, "rad/s^2",
                                                     what="an acceleration"),
                   default=None, help="acceleration limit [rad/s^2] (default: each joint's "
                                      "max speed reached in 50 ms)")
    p.add_argument("--no-root-travel", action="store_true",
                   help="play the legs as authored everywhere (default: where the animation "
                        "walks, the gait walks the legs at the root's speed and turn)")
    p.add_argument("--travel-efficiency", type=bounded_float(0.2, 1.0, "",
                                                             what="a share"),
                   default=None, metavar="SHARE",
                   help="share of the gait's no-slip stride speed the robot walks (default: "
                        "measured in MuJoCo for biped18-feetech, by speed; "
                        f"{Efficiency().forward} for any other robot, as on biped18-"
                        "dynamixel; docs/animatronics.md says how to measure yours)")
    p.add_argument("--cues", default=None, metavar="CUES.toml",
                   help="cue markers from a file of [[cue]] tables (t in seconds, name); "
                        "a glTF's own come from its animation's or scene's extras.cue "
                        "(docs/animatronics.md)")
    p.add_argument("--audio", default=None, metavar="SOUND",
                   help="soundtrack of the show (a path relative to the take)")
    p.add_argument("--audio-offset", type=audio_offset, default=0.0, metavar="SECONDS",
                   help="show time [s] at which the audio starts (default: 0)")
    p.set_defaults(set=[])
    return p


def run(args: argparse.Namespace) -> int:
    checked("ANIM", input_file, args.file)
    checked("--out", output_file, args.out)
    side = sidecar_cues(checked("--cues", input_file, args.cues)) if args.cues else ()
    if Path(args.file).suffix.lower() not in SUFFIXES:
        raise ConfigError(f"ANIM {args.file}: expected a {', '.join(SUFFIXES)} animation")
    if not is_take(args.out):
        raise ConfigError(f"--out {args.out}: a take's name ends in {SUFFIX}")
    robot = robot_from(args)
    bone_map = load_map(checked("--map", input_file, args.map), robot) if args.map \
        else by_name(robot)
    _, params = params_from(args, robot)
    hold = np.asarray(GaitEngine(robot, params).start_pose())
    efficiency = None if args.no_root_travel else efficiency_for(robot)
    if efficiency is not None and args.travel_efficiency is not None:
        efficiency = replace(efficiency, forward=args.travel_efficiency, forward_by_speed=())
    got = import_animation(args.file, robot, bone_map, hold, up=args.up,
                           min_rate=args.rate, max_accel=args.max_accel, params=params,
                           efficiency=efficiency, progress=True)
    frames = got.frames
    for w in got.walks:
        print(w.line())
        for line in w.clamped:
            print(f"  clamped: {line}")
    for v in got.violations[:SHOWN]:
        print(f"violation: {v.line()}")
    if len(got.violations) > SHOWN:
        print(f"... and {len(got.violations) - SHOWN} more violations")
    if got.violations and args.strict:
        first = got.violations[0]
        raise ConfigError(f"{args.file}: {len(got.violations)} violations (--strict); first: "
                          f"{first.joint} {first.kind} at t={first.t_worst:.3f} s")
    cues = side + (gltf_cues(args.file) if Path(args.file).suffix.lower() != ".bvh" else ())
    if cues:
        print(f"{len(cues)} cues: " + ", ".join(f"{c.t:g} s {c.name!r}" for c in cues[:5])
              + (", ..." if len(cues) > 5 else ""))
    show = Show(stream=True, audio=args.audio, audio_offset_s=args.audio_offset,
                cues=tuple(sorted(cues, key=lambda c: c.t)), up=frames.up,
                travel_m=tuple(float(v) for v in frames.travel[-1]))  # type: ignore[arg-type]
    write_stream_take(args.out, robot, params, got, show,
                      note=f"imported from {Path(args.file).name}", progress=True)
    held = [n for n in robot.joint_names if n not in frames.animated]
    fwd, left, _ = frames.travel[-1]
    fps = 1.0 / (frames.t[1] - frames.t[0]) if len(frames.t) > 1 else 0.0
    print(f"wrote {args.out}: {len(frames.t)} frames at {fps:g} fps → {len(got.t)} ticks at "
          f"{got.rate_hz:g} Hz on {robot.name}; up {frames.up}; "
          f"{len(frames.animated)} joints animated"
          + (f", {len(held)} held ({', '.join(held)})" if held else "")
          + f"; root travel {fwd:+.3f} m forward, {left:+.3f} m left"
          + ("" if args.no_root_travel else f", {len(got.walks)} walks by the gait") + "; "
          f"{len(got.violations)} violations" + (" clamped" if got.violations else ""))
    return 0
