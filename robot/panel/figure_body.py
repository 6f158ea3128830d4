"""An imported robot's stick figure, from its model (robot/previs/body_bones.py): each
limb a polyline through its hinges' axes where the model's forward kinematics puts them
(robot/body/tree.py), to its end site (a leg: the sole, then toe and heel along the foot).
A model's anchor may lie anywhere along its axis (a knee's at the hinge's far side): each
hinge is drawn at the point of its axis nearest the next point of the chain, from the end
site up (a point on the axis, so as the model has it at every angle);
the torso joins the legs' first joints, the pelvis origin and the neck (the first extra
joint's anchor, else the torso's height) and the arms' first joints. Points [m] in the
pelvis frame (REP-103), the names and shapes robot/panel/figure.py gives a box robot's.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from robot.config.joint_names import ARM_NAMES, LEG_NAMES
from robot.config.robot import RobotConfig
from robot.previs.body_bones import Placed, placed, points

Point = tuple[float, float, float]


def _limb(name: str) -> str | None:
    """The figure's line of a chain that starts at joint ``name`` (None: an extra one)."""
    side = name[:1]
    if name in LEG_NAMES:
        return f"{side}_leg"
    if name in ARM_NAMES:
        return f"{side}_arm"
    return None


def _chains(bones: list[Placed]) -> list[list[int]]:
    """Every path of bones from a bone on the pelvis to a bone that carries none."""
    children: dict[int, list[int]] = {k: [] for k in range(-1, len(bones))}
    for k, b in enumerate(bones):
        children[b.parent].append(k)
    out: list[list[int]] = []

    def walk(path: list[int]) -> None:
        below = children[path[-1]]
        if not below:
            out.append(path)
        for k in below:
            walk([*path, k])
    for k in children[-1]:
        walk([k])
    return out


def _pt(v: np.ndarray) -> Point:
    return (float(v[0]), float(v[1]), float(v[2]))


def body_figure(robot: RobotConfig, q: Sequence[float]) -> dict[str, list[Point]]:
    """Named 3-D polylines [m] for joint angles ``q`` [rad] in ``robot.joints`` order."""
    g = robot.geometry
    bones = placed(robot)
    anchors, ends, turns, axes = points(robot, bones, np.asarray([q], dtype=float))
    lines: dict[str, list[Point]] = {}
    firsts: dict[str, Point] = {}
    for chain in _chains(bones):
        root = bones[chain[0]].name
        name = _limb(root) or ("head" if "head" not in lines else root)
        while name in lines:
            name = f"{name}_2"
        tip = chain[-1]
        end = ends[tip, 0] if np.isfinite(ends[tip, 0]).all() else None
        nxt = anchors[tip, 0] if end is None else end
        drawn = []
        for k in reversed(chain):
            a, u = anchors[k, 0], axes[k, 0]
            nxt = a + u * float((nxt - a) @ u)
            drawn.append(_pt(nxt))
        pts = drawn[::-1] + ([] if end is None else [_pt(end)])
        if name.endswith("_leg") and end is not None:
            sole = end
            toe_heel = [sole + turns[tip, 0] @ np.array([dx, 0.0, 0.0])
                        for dx in (g.foot_forward + g.foot_length / 2,
                                   g.foot_forward - g.foot_length / 2)]
            pts += [_pt(toe_heel[0]), _pt(toe_heel[1]), _pt(sole)]
        lines[name] = pts
        firsts.setdefault(name, pts[0])
    neck = firsts.get("head", (0.0, 0.0, g.torso_height))
    torso = [firsts[n] for n in ("r_leg", "l_leg") if n in firsts] + [(0.0, 0.0, 0.0), neck]
    if "r_arm" in firsts and "l_arm" in firsts:
        torso += [firsts["r_arm"], neck, firsts["l_arm"]]
    lines["torso"] = torso
    return lines
