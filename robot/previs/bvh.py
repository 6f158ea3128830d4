"""Previs export: joint angles as BVH motion on the robot's own skeleton.

The skeleton (robot/previs/bones.py) is a box robot's kinematic chain from its lengths
(the pelvis as root, hips of yaw, roll and pitch about one centre, knees, ankles, the sole
as end site; chest, shoulders, elbows; extra joints as robot/config/extra_joints.py lays
them out), or an imported robot's own model: a bone per hinge at the model's joint anchor
(robot/previs/body_bones.py), one rotation channel about the hinge's axis.

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

from pathlib import Path

import numpy as np

from robot.config.robot import RobotConfig
from robot.files.atomic import write_text
from robot.previs.body_bones import body_skeleton, body_soles
from robot.previs.bones import Array, Bone, box_skeleton, box_soles

UNITS = {"cm": 100.0, "m": 1.0}
#: Robot axis → BVH rotation channel.
CHANNEL = {"x": "Zrotation", "y": "Xrotation", "z": "Yrotation"}


def to_bvh(v: tuple[float, float, float] | Array) -> Array:
    """REP-103 (x fwd, y left, z up) → BVH (X left, Y up, Z fwd)."""
    a = np.asarray(v, dtype=float)
    return a[..., [1, 2, 0]]


def skeleton(robot: RobotConfig) -> list[Bone]:
    """The robot's skeleton (robot/previs/bones.py): its model's (an imported robot,
    robot/previs/body_bones.py) or its box model's."""
    return body_skeleton(robot) if robot.body is not None else box_skeleton(robot)


def root_motion(robot: RobotConfig, q: Array) -> Array:
    """Pelvis position per frame (n, 3) [m, robot frame]: lower sole on the ground, the
    standing (lower) foot kept in place."""
    sole = body_soles(robot, q) if robot.body is not None else box_soles(robot, q)
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
        cols += [b.sign(k) * deg[:, names.index(j)] if j is not None else np.zeros(len(q))
                 for k, (_, j) in enumerate(b.axes)]
    lines += ["MOTION", f"Frames: {len(q)}", f"Frame Time: {frame_s:.6f}"]
    data = np.column_stack(cols)
    lines += [" ".join(num(v) for v in row) for row in data.tolist()]
    write_text(path, "\n".join(lines) + "\n")
    return len(q)


def resample(t: Array, q: Array, fps: float) -> Array:
    """Joint angles (n, j) at times ``t`` [s] → frames at ``fps`` [Hz] (linear)."""
    frames = np.arange(0.0, t[-1] + 1e-9, 1.0 / fps) + t[0]
    return np.column_stack([np.interp(frames, t, q[:, i]) for i in range(q.shape[1])])
