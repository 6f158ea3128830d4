"""Previs export: joint angles as BVH motion on the robot's own skeleton.

The skeleton is the robot's kinematic chain (robot.gait.ik): the pelvis (root), each hip (yaw,
roll, pitch about one centre), knee (pitch), ankle (pitch, roll) and the sole as its end
site; a chest at the shoulder height, each shoulder (pitch, roll) and elbow (pitch), the
hand as the end site; extra joints (head pan and tilt, a jaw, a tail) where
robot/config/extra_joints.py lays them out, one bone each.

Axes: BVH's convention, Y up (as Blender's and Maya's importers expect), X to the
robot's left, Z forward: (X, Y, Z) = (y, z, x) of REP-103. A proper rotation, so angles
keep their sign: a rotation about the robot's x (roll) is a Zrotation, about y (pitch)
an Xrotation, about z (yaw) a Yrotation, and each joint's channels are listed in the
order the robot composes them (hip Rz(yaw) Rx(roll) Ry(pitch) → "Yrotation Zrotation
Xrotation"). Every joint has three rotation channels (the unused ones stay 0), which
every importer reads. Lengths in centimetres by default (``units``).

Root motion: the pelvis height puts the lower sole on the ground, and the pelvis moves
so that the lower (standing) foot does not slide (x and y; no heading change), so a
walk moves forward in the scene. Angles in degrees, 6 decimals.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from robot.config.extra_joints import extra_layout, link_length
from robot.config.robot import RobotConfig
from robot.files.atomic import write_text
from robot.gait.ik import leg_fk_full

Array = npt.NDArray[np.float64]
UNITS = {"cm": 100.0, "m": 1.0}
#: Robot axis → BVH rotation channel.
CHANNEL = {"x": "Zrotation", "y": "Xrotation", "z": "Yrotation"}


@dataclass(frozen=True)
class Bone:
    """A BVH joint: ``offset`` from its parent [m, robot frame]; ``axes``: the robot axes of
    its rotations in order, each with the robot joint driving it (None: always 0)."""

    name: str
    parent: str | None
    offset: tuple[float, float, float]
    axes: tuple[tuple[str, str | None], ...]
    end: tuple[float, float, float] | None = None


def to_bvh(v: tuple[float, float, float] | Array) -> Array:
    """REP-103 (x fwd, y left, z up) → BVH (X left, Y up, Z fwd)."""
    a = np.asarray(v, dtype=float)
    return a[..., [1, 2, 0]]


def _three(axes: list[tuple[str, str | None]]) -> tuple[tuple[str, str | None], ...]:
    """Pad to three rotation channels (the missing axes first, at 0)."""
    used = {a for a, _ in axes}
    return tuple([(a, None) for a in "zxy" if a not in used] + axes)


def skeleton(robot: RobotConfig) -> list[Bone]:
    g = robot.geometry
    names = set(robot.joint_names)

    def j(name: str) -> str | None:
        return name if name in names else None
    bones = [Bone("pelvis", None, (0.0, 0.0, 0.0), ())]
    for side, sign in (("r", -1.0), ("l", 1.0)):
        bones += [
            Bone(f"{side}_hip", "pelvis", (0.0, sign * g.hip_width / 2, 0.0),
                 _three([("z", j(f"{side}_hip_yaw")), ("x", j(f"{side}_hip_roll")),
                         ("y", j(f"{side}_hip_pitch"))])),
            Bone(f"{side}_knee", f"{side}_hip", (0.0, 0.0, -g.thigh),
                 _three([("y", j(f"{side}_knee"))])),
            Bone(f"{side}_ankle", f"{side}_knee", (0.0, 0.0, -g.shin),
                 _three([("y", j(f"{side}_ankle_pitch")), ("x", j(f"{side}_ankle_roll"))]),
                 end=(0.0, 0.0, -g.ankle_height)),
        ]
    if robot.has_arms:
        bones.append(Bone("chest", "pelvis", (0.0, 0.0, g.torso_height), _three([]),
                          end=None))
        for side, sign in (("r", -1.0), ("l", 1.0)):
            bones += [
                Bone(f"{side}_shoulder", "chest", (0.0, sign * g.shoulder_width / 2, 0.0),
                     _three([("y", j(f"{side}_shoulder_pitch")),
                             ("x", j(f"{side}_shoulder_roll"))])),
                Bone(f"{side}_elbow", f"{side}_shoulder", (0.0, 0.0, -g.upper_arm),
                     _three([("y", j(f"{side}_elbow"))]), end=(0.0, 0.0, -g.forearm)),
            ]
    link = link_length(robot)
    tip = {"tail": (-link, 0.0, 0.0), "jaw": (link, 0.0, 0.0)}
    layout = extra_layout(robot)
    inner = {e.parent for e in layout}
    bones += [Bone(e.name, e.parent or "pelvis", e.offset, _three([(e.axis, e.name)]),
                   end=None if e.name in inner else tip.get(e.kind, (0.0, 0.0, link)))
              for e in layout]
    return bones


def root_motion(robot: RobotConfig, q: Array) -> Array:
    """Pelvis position per frame (n, 3) [m, robot frame]: lower sole on the ground, the
    standing (lower) foot kept in place."""
    g = robot.geometry
    names = robot.joint_names
    leg = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
    soles = []
    for side in ("r", "l"):
        cols = [q[:, names.index(f"{side}_{n}")] if f"{side}_{n}" in names
                else np.zeros(len(q)) for n in leg]
        pos, _ = leg_fk_full(g, side, tuple(cols))
        soles.append(np.stack([np.asarray(p, dtype=float) * np.ones(len(q)) for p in pos],
                              axis=1))
    sole = np.stack(soles)                              # (2, n, 3), pelvis frame
    stance = np.argmin(sole[:, :, 2], axis=0)           # the lower foot
    idx = np.arange(len(q))
    root = np.zeros((len(q), 3))
    root[:, 2] = -sole[stance, idx, 2]
    for k in range(1, len(q)):
        s = stance[k]  # that foot stays where it was in the world: the pelvis moves instead
        root[k, :2] = root[k - 1, :2] - (sole[s, k, :2] - sole[s, k - 1, :2])
    return root


def write_bvh(path: str | Path, robot: RobotConfig, q: Array, frame_s: float, *,
              units: str = "cm") -> int:
    """Write frames ``q`` (n, robot joints) [rad] at ``frame_s`` [s] per frame; returns n."""
    scale = UNITS[units]
    bones = skeleton(robot)
    names = robot.joint_names
    children: dict[str | None, list[Bone]] = {}
    for b in bones:
        children.setdefault(b.parent, []).append(b)
    lines = ["HIERARCHY"]

    def num(v: float) -> str:
        return f"{v:.6f}"

    def emit(b: Bone, depth: int) -> None:
        pad = "  " * depth
        off = to_bvh(b.offset) * scale
        lines.append(f"{pad}{'ROOT' if b.parent is None else 'JOINT'} {b.name}")
        lines.append(pad + "{")
        lines.append(f"{pad}  OFFSET {' '.join(num(v) for v in off)}")
        if b.parent is None:
            lines.append(f"{pad}  CHANNELS 6 Xposition Yposition Zposition Yrotation "
                         "Zrotation Xrotation")
        else:
            lines.append(f"{pad}  CHANNELS 3 " + " ".join(CHANNEL[a] for a, _ in b.axes))
        for c in children.get(b.name, []):
            emit(c, depth + 1)
        if b.end is not None or not children.get(b.name):
            end = to_bvh(b.end or (0.0, 0.0, 0.25 * robot.geometry.thigh)) * scale
            lines.extend([f"{pad}  End Site", pad + "  {",
                          f"{pad}    OFFSET {' '.join(num(v) for v in end)}", pad + "  }"])
        lines.append(pad + "}")
    emit(bones[0], 0)
    root = to_bvh(root_motion(robot, q)) * scale
    deg = np.degrees(q)
    cols: list[Array] = [root[:, 0], root[:, 1], root[:, 2]] + [np.zeros(len(q))] * 3
    for b in bones[1:]:
        cols += [deg[:, names.index(j)] if j is not None else np.zeros(len(q))
                 for _, j in b.axes]
    lines += ["MOTION", f"Frames: {len(q)}", f"Frame Time: {frame_s:.6f}"]
    data = np.column_stack(cols)
    lines += [" ".join(num(v) for v in row) for row in data.tolist()]
    write_text(path, "\n".join(lines) + "\n")
    return len(q)


def resample(t: Array, q: Array, fps: float) -> Array:
    """Joint angles (n, j) at times ``t`` [s] → frames at ``fps`` [Hz] (linear)."""
    frames = np.arange(0.0, t[-1] + 1e-9, 1.0 / fps) + t[0]
    return np.column_stack([np.interp(frames, t, q[:, i]) for i in range(q.shape[1])])
