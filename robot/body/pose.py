"""A model seen in the robot frame at chosen joint angles (the offsets the importer has
found so far), and the sole of a foot: the lowest face of its shapes.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from robot.body.limbs import link_points
from robot.body.tree import Array, BodyTree, Shape, quat_to_matrix

Z = np.array([0.0, 0.0, 1.0])


class Pose:
    """The model at the offsets found so far, seen in the robot frame."""

    def __init__(self, tree: BodyTree, axes: Array) -> None:
        self.tree, self.axes = tree, axes
        self.angles: dict[str, float] = {}
        self.update()

    def update(self) -> None:
        self.pos, self.rot = self.tree.poses(self.angles)

    def axis(self, link: int) -> Array:
        hinge = self.tree.links[link].joint
        assert hinge is not None
        return self.axes @ self.rot[link] @ np.asarray(hinge.axis, float)

    def anchor(self, link: int) -> Array:
        hinge = self.tree.links[link].joint
        assert hinge is not None
        return self.axes @ (self.pos[link] + self.rot[link] @ np.asarray(hinge.pos, float))

    def turn(self, link: int, about: Array, angle: float) -> None:
        """Turn ``link``'s hinge by ``angle`` [rad] about the robot axis ``about``."""
        hinge = self.tree.links[link].joint
        assert hinge is not None
        sign = 1.0 if float(self.axis(link) @ about) > 0 else -1.0
        self.angles[hinge.name] = self.angles.get(hinge.name, 0.0) + sign * angle
        self.update()

    def points(self, links: list[int]) -> Array:
        return np.concatenate([link_points(self.tree, i, self.pos, self.rot) for i in links]) @ self.axes.T


def sole_normal(pose: Pose, foot_links: list[int]) -> Array:
    """The downward normal of the lowest face of the foot's shapes (robot frame): a box's
    face (the face of the lowest box that faces down most), else the plane through a
    hull's lowest points (refit until it settles: a tilted sole's lowest band widens)."""
    tree = pose.tree
    boxes = [(i, s) for i in foot_links for s in tree.links[i].shapes if s.kind == "box"]
    if boxes:
        def lowest(item: tuple[int, Shape]) -> float:
            return float(link_points_one(pose, item[0], item[1])[:, 2].min())
        i, box = min(boxes, key=lowest)
        rot = pose.axes @ pose.rot[i] @ quat_to_matrix(box.quat)
        normals = np.concatenate([rot.T, -rot.T])
        return normals[int(np.argmax(normals @ -Z))]
    return hull_sole(pose.points(foot_links))


def hull_sole(pts: Array, *, lowest: int = 40) -> Array:
    """The downward normal of the convex hull face that faces down within 60 deg and has
    the most of the points on it (a flat sole), found among the planes through three of
    the ``lowest`` points that every point lies above."""
    low = pts[np.argsort(pts[:, 2])[:lowest]]
    n = len(low)
    i, j, k = np.array([(a, b, c) for a in range(n) for b in range(a + 1, n)
                        for c in range(b + 1, n)]).T
    normal = np.cross(low[j] - low[i], low[k] - low[i])
    size = np.linalg.norm(normal, axis=1)
    ok = size > 1e-9
    normal = normal[ok] / size[ok, None]
    normal *= np.where(normal[:, 2] < 0, 1.0, -1.0)[:, None]   # pointing down
    base = low[i[ok]]
    height = np.einsum("pnk,pk->pn", pts[None, :, :] - base[:, None, :], normal)
    support = (height.max(axis=1) <= 1e-6) & (normal[:, 2] < -0.5)
    if not support.any():
        return -Z
    on = (np.abs(height) < 1e-4).sum(axis=1)
    score = np.where(support, on + 1e-3 * -normal[:, 2], -1.0)
    return normal[int(np.argmax(score))]


def link_points_one(pose: Pose, i: int, shape: Shape) -> Array:
    """One shape's points in the robot frame (root origin) [m]."""
    link = pose.tree.links[i]
    one = BodyTree((dataclasses.replace(link, parent=-1, shapes=(shape,)),))
    pts = link_points(one, 0, pose.pos[i:i + 1], pose.rot[i:i + 1])
    return pts @ pose.axes.T


