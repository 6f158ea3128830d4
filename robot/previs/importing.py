"""`biped import` without the command line: an animation file (BVH, glTF) → the robot's
joint stream at the control rate, its violations, and the take that `biped play` streams.

The stream's rate is the smallest whole multiple of the animation's frame rate at or
above ``min_rate`` (every frame is a tick: a round trip compares frame for frame).
Between the frames of a sampled animation (a BVH, a glTF of LINEAR tracks: ``Rig.sampled``)
the joints follow the C2 cubic spline through them (robot/motion/interp.py ``spline``: a
peak between two frames comes back, the acceleration does not step at each frame; kept
inside the joint limits where the frames are, so no limit is crossed that the frames do
not cross); between sparse keyframes (a glTF's CUBICSPLINE or STEP tracks) the monotone
cubic (``smooth``: no overshoot). Where the
animation walks, the gait's travel is planned from the root's motion (robot/previs/
travel.py) and written as the take's parameter timeline (robot/motion/show_walk.py).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.files.atomic import OutputFile
from robot.motion.interp import smooth
from robot.motion.kinks import sampled
from robot.motion.show import Show
from robot.motion.takes import TakeHeader
from robot.previs.bone_map import BoneMap
from robot.previs.bvh_read import read_bvh
from robot.previs.feet import rig_motion
from robot.previs.gltf_read import read_gltf
from robot.previs.retarget import Retargeted, retarget, robot_leg, robot_scale
from robot.previs.rig import Array, Rig
from robot.previs.travel import Efficiency, WalkPlan, plan_walk, travel
from robot.previs.violations import Violation, check, clamp
from robot.previs.walk_spans import walks

SUFFIXES = (".bvh", ".glb", ".gltf")
#: Highest take rate [Hz] (robot.motion.takes accepts up to 2000).
MAX_RATE_HZ = 2000.0
#: Most ticks in an imported take: an hour at 400 Hz (~0.6 GB of take for 18 joints).
MAX_TICKS = 1_440_000
#: Takes this long show a progress bar while written [ticks]; rows formatted at a time.
PROGRESS_TICKS = 100_000
WRITE_ROWS = 10_000


def read_rig(path: str | Path, *, progress: bool = False) -> Rig:
    suffix = Path(path).suffix.lower()
    if suffix not in SUFFIXES:
        raise ConfigError(f"{path}: expected a {', '.join(SUFFIXES)} animation")
    rig = read_bvh(path, progress=progress) if suffix == ".bvh" else read_gltf(path)
    if rig.frames < 2:
        raise ConfigError(f"{path}: {rig.frames} frame: a pose, not an animation; a take "
                          "needs at least 2 frames (a pose: biped capture, or a keyframe "
                          "file for biped play)")
    return rig


@dataclass(frozen=True)
class Imported:
    """The frames as retargeted (``frames``), the stream at ``rate_hz`` before (``raw``)
    and after the clamp (``q``) at times ``t`` [s], the violations of ``raw``, and where
    the gait walks the legs (``walks``; none without root travel)."""

    frames: Retargeted
    rate_hz: float
    t: Array
    raw: Array
    q: Array
    violations: tuple[Violation, ...]
    walks: tuple[WalkPlan, ...] = ()


def stream_rate(frame_s: float, min_rate: float) -> float:
    fps = 1.0 / frame_s
    rate = fps * max(1, math.ceil(min_rate / fps - 1e-9))
    if rate > MAX_RATE_HZ:
        raise ConfigError(f"animation at {fps:g} fps: a stream of {rate:g} Hz is above "
                          f"{MAX_RATE_HZ:g} Hz; give a lower --rate")
    return rate


def import_animation(path: str | Path, robot: RobotConfig, bone_map: BoneMap, hold: Array,
                     *, up: str | None = None, min_rate: float = 200.0,
                     max_accel: float | None = None, params: GaitParams | None = None,
                     efficiency: Efficiency | None = None, progress: bool = False) -> Imported:
    """``params`` and ``efficiency`` given: the walks become the gait's travel;
    ``progress``: a bar while a long BVH is read."""
    rig = read_rig(path, progress=progress)
    frames = retarget(rig, robot, bone_map, hold, up=up)
    rate = stream_rate(rig.frame_s, min_rate)
    n = int(round(frames.t[-1] * rate)) + 1
    if n > MAX_TICKS:
        raise ConfigError(f"{path}: {frames.t[-1]:.0f} s at {rate:g} Hz is {n} ticks, more "
                          f"than a take holds ({MAX_TICKS}); lower --rate or cut the animation")
    t = np.arange(n) / rate
    raw = (sampled(frames.t, frames.q, t, lo=np.array([j.min_rad for j in robot.joints]),
                  hi=np.array([j.max_rad for j in robot.joints]))
           if rig.sampled else smooth(frames.t, frames.q, t))
    found = check(robot, t, raw, max_accel=max_accel, joints=frames.animated)
    q = clamp(robot, t, raw, max_accel=max_accel) if found else raw
    plans: tuple[WalkPlan, ...] = ()
    if params is not None and efficiency is not None:
        c = rig.orient(up or bone_map.up)
        motion = rig_motion(rig, c, robot_scale(rig, c, robot))
        plans = tuple(plan_walk(w, motion, robot, params, efficiency)
                      for w in walks(motion, robot_leg(robot)))
    return Imported(frames, rate, t, raw, q, tuple(found), plans)


def write_stream_take(path: str | Path, robot: RobotConfig, params: GaitParams,
                      imported: Imported, show: Show, *, note: str = "",
                      progress: bool = False) -> None:
    """The take: a header with the show (``stream``: play the joint angles as they are),
    the walks' timeline (robot/motion/show_walk.py) and one stream line per tick [rad, 8
    decimals]. Written line by line to a temporary name beside ``path``, renamed when
    whole (a take is whole or absent); ``progress``: a bar (tqdm) over a long take's ticks."""
    header = TakeHeader(robot=robot.name, robot_file=robot.source,
                        joints=robot.joint_names, rate_hz=imported.rate_hz, read_every=10,
                        gait="import", params=params, note=note, show=show.as_json())
    out = OutputFile(path, buffer_bytes=1 << 20)
    n = len(imported.t)
    try:
        out.open()
        with tqdm(total=n, unit="tick", leave=False, desc=f"writing {Path(path).name}",
                  disable=not progress or n < PROGRESS_TICKS) as bar:
            out.write(json.dumps(header.as_json()) + "\n")
            for event in travel(imported.walks).timeline(imported.rate_hz):
                out.write(json.dumps(event) + "\n")
            for start in range(0, n, WRITE_ROWS):
                ts = imported.t[start:start + WRITE_ROWS].tolist()
                qs = imported.q[start:start + WRITE_ROWS].tolist()
                out.write("".join(_tick_line(start + k, t, row)
                                  for k, (t, row) in enumerate(zip(ts, qs, strict=True))))
                bar.update(len(ts))
        out.commit(partial=False)                 # a take is whole or absent
    except OSError as e:
        out.discard()
        raise ConfigError(f"--out {path}: cannot write it: {e.strerror or e}") from None
    except BaseException:
        out.discard()
        raise


def _tick_line(tick: int, t: float, row: list[float]) -> str:
    """One stream line, as ``json.dumps`` writes it (a finite float's JSON is its repr)."""
    q = ", ".join(repr(round(v, 8)) for v in row)
    return f'{{"tick": {tick}, "t": {round(t, 9)!r}, "state": "show", "q": [{q}]}}\n'
