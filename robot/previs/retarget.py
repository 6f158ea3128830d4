"""Retargeting: an animated skeleton (robot/previs/rig.py) onto a robot's joints through a
bone map (robot/previs/bone_map.py).

Each mapped bone's rotation from rest, turned into robot axes (R = C D C^T with C from
``Rig.orient``), is decomposed onto the joint axes in the map's order (robot/previs/
rotations.py; of its two solutions the one that leaves the axes the bone does not use at 0,
so a shoulder raised past 90 degrees stays one pitch, not a flip); joint = sign x angle +
offset. Joints the map leaves out hold ``hold``
(the gait's standing pose). The root's travel is scaled to the robot by the ratio of the
two legs' lengths (the rig's: the root's height above its lowest chain end at rest).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.previs.bone_map import BoneMap
from robot.previs.rig import Array, Rig
from robot.previs.rotations import decompose, other_solution


@dataclass(frozen=True)
class Retargeted:
    """t (n,) [s] from the first frame; q (n, robot joints) [rad]; animated: the joints
    the file drives (the rest hold); travel (n, 3) [m]: the root's path in robot axes,
    scaled to the robot; up: the rig's up axis as found (e.g. "+Y")."""

    t: Array
    q: Array
    animated: tuple[str, ...]
    travel: Array
    up: str


def _find(rig: Rig, bone: str) -> int | None:
    folded = {n.casefold(): i for i, n in enumerate(rig.names)}
    return folded.get(bone.casefold())


def robot_leg(robot: RobotConfig) -> float:
    """The robot's leg [m]: hip to sole with straight knees."""
    g = robot.geometry
    return g.thigh + g.shin + g.ankle_height


def robot_scale(rig: Rig, c: Array, robot: RobotConfig) -> float:
    """Robot metres per file unit: the ratio of the two legs' lengths (the rig's: the
    root's height above its lowest chain end at rest, along up ``c[2]``)."""
    pos, _ = rig.rest_positions()
    leaves = rig.leaves()
    rig_leg = float((pos[0] - leaves.min(axis=0)) @ c[2]) if len(leaves) else 0.0
    if rig_leg <= 0:
        rig_leg = float(np.ptp(np.vstack([pos, leaves]) @ c[2]))
    return robot_leg(robot) / rig_leg if rig_leg > 0 else 1.0


def retarget(rig: Rig, robot: RobotConfig, bone_map: BoneMap, hold: Array, *,
             up: str | None = None) -> Retargeted:
    c = rig.orient(up or bone_map.up)
    names = robot.joint_names
    q = np.tile(np.asarray(hold, dtype=float), (rig.frames, 1))
    animated: list[str] = []
    missing: list[str] = []
    for bone, (order, maps) in bone_map.bones().items():
        b = _find(rig, bone)
        if b is None:
            missing.append(bone)
            continue
        r = c @ rig.pose[:, b] @ c.T
        angles = decompose(order, r)
        free = [col for col, m in enumerate(maps) if m is None]
        if free:   # a bone turned past 90 deg: the solution that leaves unused axes at 0
            alt = other_solution(angles)
            use = np.abs(alt[:, free]).sum(axis=1) < np.abs(angles[:, free]).sum(axis=1)
            angles[use] = alt[use]
        for col, m in enumerate(maps):
            if m is not None:
                q[:, names.index(m.joint)] = m.sign * angles[:, col] + m.offset
                animated.append(m.joint)
    if not animated:
        raise ConfigError(f"{rig.source}: no bone of the map ({bone_map.source}) is in the "
                          f"file (missing: {', '.join(missing[:6])}); bones in the file: "
                          f"{', '.join(rig.names[:12])}; give --map MAP.toml")
    travel = (rig.root - rig.root[0]) @ c.T * robot_scale(rig, c, robot)
    axis = int(np.argmax(np.abs(c[2])))
    sign = "+" if c[2, axis] > 0 else "-"
    driven = tuple(n for n in names if n in animated)
    t = np.asarray(np.arange(rig.frames) * rig.frame_s, dtype=np.float64)
    return Retargeted(t, q, driven, travel,
                      f"{sign}{'XYZ'[axis]}")
