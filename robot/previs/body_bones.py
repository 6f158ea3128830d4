"""An imported robot's skeleton, from its model's body (robot/body/model.py, tree.py):
one bone per hinge, named after the robot's joint it is (``r_knee``, ``head_tilt``), at
the hinge's anchor in the model (the point MuJoCo calls the joint's anchor), in the
robot frame (REP-103, from the pelvis origin) at the project's zero pose (model angles
``model_offset``: legs straight and hanging). A bone's parent is the bone of the nearest
hinge above it in the model's tree (the root link and the links welded to it: the
``pelvis``, the root bone, at the pelvis origin).

A bone turns about its hinge's axis at the zero pose, which the importer found along a
robot axis (x, y or z, within robot.body.limbs.SNAP_TOL): that axis, with sign -1 where the
hinge turns about its minus direction (an axis off every robot axis is taken as the
nearest, with a warning). By the product of exponentials, the bones then sit where the
model's own forward kinematics puts the hinges at every angle. A chain end is an end site:
the sole (the importer's ``r_sole``/``l_sole`` frame), else the link's first frame, else
its centre of mass.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from robot.body.limbs import SNAP_TOL
from robot.body.model import BodyModel
from robot.config.model_angles import ModelAngles
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.previs.bones import Array, Bone, three

log = logging.getLogger(__name__)
#: An end site nearer its bone than this is left to the writer's default [m].
MIN_END = 1e-3


@dataclass(frozen=True)
class Placed:
    """A bone of the model: ``link`` the link its hinge moves; ``parent`` the parent
    bone's index (-1: the pelvis); ``anchor``: the hinge's point in that link [m];
    ``axis``/``sign``: the robot axis it turns about; ``end``: its end site as (link,
    point in that link [m]), or None."""

    name: str
    link: int
    parent: int
    anchor: tuple[float, float, float]
    axis: str
    sign: float
    end: tuple[int, tuple[float, float, float]] | None


def body_of(robot: RobotConfig) -> BodyModel:
    if robot.body is None:
        raise ConfigError(f"{robot.source}: {robot.name} has no [model] (a box robot)")
    return robot.body


def placed(robot: RobotConfig) -> list[Placed]:
    """The model's bones in tree order, parents first."""
    body = body_of(robot)
    tree = body.tree
    by_hinge = {j.model_joint: j for j in robot.joints}
    _, rot = tree.poses(ModelAngles.of(robot).zero())
    r, _ = body.root_to_pelvis()
    bone_of: dict[int, int] = {}     # link → index of the bone it moves with (-1: pelvis)
    out: list[Placed] = []
    for i, link in enumerate(tree.links):
        if link.parent < 0 or link.joint is None:
            bone_of[i] = -1 if link.parent < 0 else bone_of[link.parent]
            continue
        joint = by_hinge[link.joint.name]
        axis = r @ rot[i] @ np.asarray(link.joint.axis, float) * joint.model_sign
        axis = axis / np.linalg.norm(axis)
        k = int(np.argmax(np.abs(axis)))
        off = math.acos(min(abs(float(axis[k])), 1.0))
        if off > SNAP_TOL:
            log.warning("%s: joint %s (model joint %r) turns %.1f deg off the robot's %s "
                        "axis: the skeleton turns it about %s", robot.source, joint.name,
                        joint.model_joint, math.degrees(off), "xyz"[k], "xyz"[k])
        bone_of[i] = len(out)
        out.append(Placed(joint.name, i, bone_of[link.parent],
                          tuple(float(v) for v in link.joint.pos),  # type: ignore[arg-type]
                          "xyz"[k], 1.0 if axis[k] > 0 else -1.0, None))
    carried = {b.parent for b in out}
    for n, b in enumerate(out):
        if n not in carried:
            links = [i for i, owner in bone_of.items() if owner == n]
            out[n] = Placed(b.name, b.link, b.parent, b.anchor, b.axis, b.sign,
                            _end(robot, links))
    return out


def _end(robot: RobotConfig, links: list[int]) -> tuple[int, tuple[float, float, float]] | None:
    """A chain end: a sole frame on ``links``, else the first frame, else the centre of
    mass of the first link that has one."""
    tree = body_of(robot).tree
    frames = [(i, f) for i in links for f in tree.links[i].frames]
    soles = [(i, f) for i, f in frames if f.name in ("r_sole", "l_sole")]
    for i, f in soles or frames:
        return i, f.pos
    for i in links:
        inertial = tree.links[i].inertial
        if inertial is not None:
            return i, inertial.com
    return None


def points(robot: RobotConfig, bones: list[Placed], q: Array
           ) -> tuple[Array, Array, Array, Array]:
    """At joint angles ``q`` (n, robot joints) [rad]: each bone's anchor (B, n, 3) and end
    site (B, n, 3; NaN where none) [m, pelvis frame], each bone link's rotation from its
    zero-pose orientation (B, n, 3, 3) and its hinge's unit axis (B, n, 3), in the robot's
    axes."""
    body = body_of(robot)
    angles = ModelAngles.of(robot)
    n = len(q)
    pos, rot = body.tree.poses_many(angles.named(q), n)
    _, rot0 = body.tree.poses(angles.zero())
    r, p = body.root_to_pelvis()
    anchors = np.full((len(bones), n, 3), np.nan)
    ends = np.full((len(bones), n, 3), np.nan)
    turns = np.zeros((len(bones), n, 3, 3))
    axes = np.zeros((len(bones), n, 3))
    for k, b in enumerate(bones):
        hinge = body.tree.links[b.link].joint
        assert hinge is not None
        axes[k] = rot[b.link] @ (np.asarray(hinge.axis) / np.linalg.norm(hinge.axis)) @ r.T
        at = pos[b.link] + rot[b.link] @ np.asarray(b.anchor)
        anchors[k] = (at - p) @ r.T
        if b.end is not None:
            i, local = b.end
            ends[k] = (pos[i] + rot[i] @ np.asarray(local) - p) @ r.T
        turns[k] = r @ rot[b.link] @ rot0[b.link].T @ r.T
    return anchors, ends, turns, axes


def body_skeleton(robot: RobotConfig) -> list[Bone]:
    """The model's skeleton (the module docstring) as bones with rest offsets [m]."""
    bones = placed(robot)
    anchors, ends, _, _ = points(robot, bones, np.zeros((1, len(robot.joints))))
    out = [Bone("pelvis", None, (0.0, 0.0, 0.0), ())]
    for k, b in enumerate(bones):
        base = anchors[b.parent, 0] if b.parent >= 0 else np.zeros(3)
        end = ends[k, 0] - anchors[k, 0]
        out.append(Bone(b.name, out[b.parent + 1].name, _vec(anchors[k, 0] - base),
                        three([(b.axis, b.name)]),
                        end=_vec(end) if b.end is not None and np.linalg.norm(end) >= MIN_END
                        else None,
                        signs=(1.0, 1.0, b.sign)))
    return out


def body_soles(robot: RobotConfig, q: Array) -> Array:
    """The right and left sole points (2, n, 3) [m, pelvis frame] at joint angles ``q`` (n,
    robot joints) [rad]: the model's ``r_sole``/``l_sole`` frames (robots imported by
    `biped robots import` carry them)."""
    body = body_of(robot)
    where = {f.name: (i, f.pos) for i, link in enumerate(body.tree.links) for f in link.frames}
    missing = [s for s in ("r_sole", "l_sole") if s not in where]
    if missing:
        raise ConfigError(f"{robot.source}: [model] has no {missing[0]!r} frame (`biped robots "
                          "import` writes one on each foot); import the model again")
    pos, rot = body.tree.poses_many(ModelAngles.of(robot).named(q), len(q))
    r, p = body.root_to_pelvis()
    out = []
    for side in ("r_sole", "l_sole"):
        i, local = where[side]
        out.append((pos[i] + rot[i] @ np.asarray(local) - p) @ r.T)
    return np.stack(out)


def _vec(v: Array) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))
