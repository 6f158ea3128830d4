"""The skeleton the previs export writes (BVH, glTF) and the import reads back by name:
bones, their rest offsets, which robot joint turns each about which axis, and where the
soles are at given joint angles (the root motion puts the lower one on the ground).

Two sources, as for the body (robot/body/tree.py): a box robot's skeleton is its kinematic
chain from the robot file's lengths (``box_skeleton``): the pelvis (root), each hip (yaw,
roll, pitch about one centre), knee (pitch), ankle (pitch, roll) and the sole as its end
site; a chest at the shoulder height, each shoulder (pitch, roll) and elbow (pitch), the
hand as the end site; extra joints (head pan and tilt, a jaw, a tail) where
robot/config/extra_joints.py lays them out, one bone each. An imported robot's is its
model's own (robot/previs/body_bones.py): a bone per hinge at the model's joint anchor.

Offsets are in the robot frame (REP-103: x forward, y left, z up) [m] at the zero pose, in
which every bone's frame is the robot's: a rotation channel turns about a robot axis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from robot.config.extra_joints import extra_layout, link_length
from robot.config.robot import RobotConfig
from robot.gait.ik import leg_fk_full

Array = npt.NDArray[np.float64]
LEG = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")


@dataclass(frozen=True)
class Bone:
    """A skeleton joint: ``offset`` from its parent [m, robot frame]; ``axes``: the robot
    axes of its rotations in order, each with the robot joint driving it (None: always 0);
    ``signs``: per axis, +1 where the joint turns about +axis, -1 where about -axis (an
    imported model's hinge along -y: the channel is minus the joint's angle; empty: all
    +1); ``end``: its end site's offset [m] (None: none, or the writer's default)."""

    name: str
    parent: str | None
    offset: tuple[float, float, float]
    axes: tuple[tuple[str, str | None], ...]
    end: tuple[float, float, float] | None = None
    signs: tuple[float, ...] = ()

    def sign(self, k: int) -> float:
        """The sign of the ``k``-th axis (+1 or -1)."""
        return self.signs[k] if self.signs else 1.0


def three(axes: list[tuple[str, str | None]]) -> tuple[tuple[str, str | None], ...]:
    """Pad to three rotation channels (the missing axes first, at 0)."""
    used = {a for a, _ in axes}
    return tuple([(a, None) for a in "zxy" if a not in used] + axes)


def box_skeleton(robot: RobotConfig) -> list[Bone]:
    """A box robot's skeleton from its geometry (see the module docstring)."""
    g = robot.geometry
    names = set(robot.joint_names)

    def j(name: str) -> str | None:
        return name if name in names else None
    bones = [Bone("pelvis", None, (0.0, 0.0, 0.0), ())]
    for side, sign in (("r", -1.0), ("l", 1.0)):
        bones += [
            Bone(f"{side}_hip", "pelvis", (0.0, sign * g.hip_width / 2, 0.0),
                 three([("z", j(f"{side}_hip_yaw")), ("x", j(f"{side}_hip_roll")),
                        ("y", j(f"{side}_hip_pitch"))])),
            Bone(f"{side}_knee", f"{side}_hip", (0.0, 0.0, -g.thigh),
                 three([("y", j(f"{side}_knee"))])),
            Bone(f"{side}_ankle", f"{side}_knee", (0.0, 0.0, -g.shin),
                 three([("y", j(f"{side}_ankle_pitch")), ("x", j(f"{side}_ankle_roll"))]),
                 end=(0.0, 0.0, -g.ankle_height)),
        ]
    if robot.has_arms:
        bones.append(Bone("chest", "pelvis", (0.0, 0.0, g.torso_height), three([]),
                          end=None))
        for side, sign in (("r", -1.0), ("l", 1.0)):
            bones += [
                Bone(f"{side}_shoulder", "chest", (0.0, sign * g.shoulder_width / 2, 0.0),
                     three([("y", j(f"{side}_shoulder_pitch")),
                            ("x", j(f"{side}_shoulder_roll"))])),
                Bone(f"{side}_elbow", f"{side}_shoulder", (0.0, 0.0, -g.upper_arm),
                     three([("y", j(f"{side}_elbow"))]), end=(0.0, 0.0, -g.forearm)),
            ]
    link = link_length(robot)
    tip = {"tail": (-link, 0.0, 0.0), "jaw": (link, 0.0, 0.0)}
    layout = extra_layout(robot)
    inner = {e.parent for e in layout}
    bones += [Bone(e.name, e.parent or "pelvis", e.offset, three([(e.axis, e.name)]),
                   end=None if e.name in inner else tip.get(e.kind, (0.0, 0.0, link)))
              for e in layout]
    return bones


def box_soles(robot: RobotConfig, q: Array) -> Array:
    """A box robot's right and left sole points (2, n, 3) [m, pelvis frame] at joint angles
    ``q`` (n, robot joints) [rad]."""
    names = robot.joint_names
    out = []
    for side in ("r", "l"):
        cols = [q[:, names.index(f"{side}_{n}")] if f"{side}_{n}" in names
                else np.zeros(len(q)) for n in LEG]
        pos, _ = leg_fk_full(robot.geometry, side, tuple(cols))
        out.append(np.stack([np.asarray(p, dtype=float) * np.ones(len(q)) for p in pos],
                            axis=1))
    return np.stack(out)
