"""An imported robot's own body, as its robot file carries it: the body tree in the
model's terms, how the robot's frame sits in the model's root frame, and the legs as the
IK solves them (robot/body/legs.py).

The joints' names and conventions in the model (``model_joint``, ``model_sign``,
``model_offset``: model angle = model_sign * angle + model_offset) live on each joint of
the robot file (robot/config/robot.py ``JointConfig``), next to its servo; given them,
``BodyModel.robot_tree`` is the body in the robot's terms, as the box model is
(robot/body/boxes.py), for the simulation to build.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np

from robot.body.legs import LegChain
from robot.body.tree import (
    IDENTITY_QUAT,
    ORIGIN,
    Array,
    BodyTree,
    Frame,
    Hinge,
    Inertial,
    Link,
    Quat,
    Vec3,
    matrix_to_quat,
    quat_to_matrix,
)


@dataclass(frozen=True)
class JointTerms:
    """A model's joint in the robot's terms: name: the project's (``r_knee``); sign,
    offset: model angle = sign * angle + offset [rad]; range: the robot file's limits
    [rad]."""

    name: str
    sign: int
    offset: float
    range: tuple[float, float]


@dataclass(frozen=True)
class BodyModel:
    """tree: the links; axes: the robot's x, y, z as rows in the model's root frame;
    pelvis: the pelvis origin in the model's root frame [m]; legs: (right, left) in the
    pelvis frame; file: the model file it was imported from (its name, as the user gave
    it); source, licence: where the model comes from and under which licence (free text,
    kept with the numbers)."""

    tree: BodyTree
    axes: tuple[Vec3, Vec3, Vec3]
    pelvis: Vec3
    legs: tuple[LegChain, LegChain]
    file: str = ""
    source: str = ""
    licence: str = ""

    def root_to_pelvis(self) -> tuple[Array, Array]:
        """(R, p): a point x in the model's root frame is R @ (x - p) in the pelvis
        frame."""
        return np.asarray(self.axes, float), np.asarray(self.pelvis, float)

    def pelvis_to_root(self, point: Array) -> Array:
        """A point [m] (..., 3) in the pelvis frame, in the model's root frame."""
        r, p = self.root_to_pelvis()
        return np.asarray(point, float) @ r + p

    def robot_tree(self, joints: Mapping[str, JointTerms]) -> BodyTree:
        """The tree in the robot's terms, by model joint name ``joints`` (every hinge of
        the tree must be there):

        - the root link's frame is the pelvis frame: its inertial, shapes and frames and
          its children's frames re-expressed in it (the root's own pose is dropped: the
          simulation stands it);
        - each hinge is named after the project's joint and turns the project's way: its
          axis is ``sign`` times the model's, its ``ref`` ``-sign * offset`` (so the
          angle is the project's and the links stand as the model draws them at the
          model's zero), its range the robot file's;
        - shapes lose their names (a model's own names could clash with the ones the
          simulation gives: ``torso``, ``r_foot``); every quaternion is re-derived
          through its matrix (``matrix_to_quat``: w >= 0)."""
        r, p = self.root_to_pelvis()
        links = [_relink(link, joints, r, p, depth=min(i, 1) if link.parent <= 0 else 2)
                 for i, link in enumerate(self.tree.links)]
        return BodyTree(tuple(links), source=self.tree.source, excludes=self.tree.excludes)


def _vec(x: Array) -> Vec3:
    return (float(x[0]), float(x[1]), float(x[2]))


def _relink(link: Link, joints: Mapping[str, JointTerms], r: Array, p: Array, *,
            depth: int) -> Link:
    """``link`` in the robot's terms (``BodyModel.robot_tree``); (r, p): the root frame
    into the pelvis frame; depth: 0 the root, 1 a link on the root, 2 one further out."""
    turn = r if depth == 0 else np.eye(3)

    def move(v: Vec3) -> Vec3:
        return _vec(r @ (np.asarray(v, float) - p) if depth == 0 else np.asarray(v, float))

    def spin(q: Quat) -> Quat:
        return matrix_to_quat(turn @ quat_to_matrix(q))

    inertial = link.inertial
    if inertial is not None and depth == 0:
        f = r @ inertial.matrix() @ r.T
        inertial = Inertial(inertial.mass, move(inertial.com),
                            (float(f[0, 0]), float(f[1, 1]), float(f[2, 2]), float(f[0, 1]),
                             float(f[0, 2]), float(f[1, 2])))
    shapes = tuple(replace(sh, pos=move(sh.pos), quat=spin(sh.quat), name="")
                   for sh in link.shapes)
    frames = tuple(Frame(f.name, move(f.pos), spin(f.quat)) for f in link.frames)
    pos, quat = link.pos, link.quat
    if depth == 0:
        pos, quat = ORIGIN, IDENTITY_QUAT
    elif depth == 1:
        pos = _vec(r @ (np.asarray(link.pos, float) - p))
        quat = matrix_to_quat(r @ quat_to_matrix(link.quat))
    joint = link.joint
    if joint is not None:
        t = joints[joint.name]
        axis = _vec(np.asarray(joint.axis, float) * t.sign)
        joint = Hinge(t.name, axis, joint.pos, t.range, joint.effort, joint.velocity,
                      ref=-t.sign * t.offset)
    return Link(link.name, link.parent, pos, quat, inertial, joint, shapes, frames)
