"""A body tree's limbs and the robot's own axes, found from the model alone.

The torso is the root link and every link welded to it. A limb is what hangs from the
torso through a hinge: its hinges in order from the torso out (a serial chain; where it
branches, as a head does into antennas, the chain follows the branch that goes farthest
and the rest are the limb's side hinges). Each limb's end point is the farthest point of
its chain's last link (its shapes' corners, else its origin) at the model's zero pose.

The legs are the two limbs of at least five hinges whose ends lie farthest from the torso;
up points from their ends to the torso (snapped to the root frame's nearest axis), left
from the right leg's hip to the left one's (a leg is left by its names: ``l_``, ``left``,
``_l``, ``L_``...), forward completes REP-103 (x forward, y left, z up).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from robot.body.tree import Array, BodyTree, quat_to_matrix
from robot.errors import ConfigError

LEFT = re.compile(r"(^l[_.\-]|[_.\-]l$|[_.\-]l[_.\-]|left|^l(?=[A-Z]))", re.IGNORECASE)
RIGHT = re.compile(r"(^r[_.\-]|[_.\-]r$|[_.\-]r[_.\-]|right|^r(?=[A-Z]))", re.IGNORECASE)
#: How far an axis may be from the root frame's axis it is snapped to [rad] (0.5 deg).
SNAP_TOL = 0.0087
#: How far up and left, found from where the feet and hips are, may be from the root axis
#: they are snapped to [rad] (30 deg: feet ahead of the torso's origin tilt the first).
ROUGH_TOL = math.radians(30.0)
AXES = np.eye(3)


@dataclass(frozen=True)
class Limb:
    """hinges: link indices of the chain's hinges, torso outward; side: extra hinges off
    the chain (link indices); end: the chain's farthest point in the root frame [m]."""

    hinges: tuple[int, ...]
    side: tuple[int, ...]
    end: tuple[float, float, float]

    @property
    def last(self) -> int:
        return self.hinges[-1]


def torso_links(tree: BodyTree) -> set[int]:
    """The root and every link welded to it."""
    out = {0}
    for i, link in enumerate(tree.links):
        if link.parent in out and link.joint is None:
            out.add(i)
    return out


def link_points(tree: BodyTree, i: int, pos: Array, rot: Array) -> Array:
    """Corners of link ``i``'s shapes in the root frame (its origin if it has none) [m]."""
    pts: list[Array] = []
    for s in tree.links[i].shapes:
        r = rot[i] @ quat_to_matrix(s.quat)
        c = pos[i] + rot[i] @ np.asarray(s.pos, float)
        if s.kind == "hull":
            pts.extend(c + np.asarray(s.vertices, float) @ r.T)
        elif s.kind == "box":
            corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
            pts.extend(c + (corners * s.size[:3]) @ r.T)
        else:
            radius = s.size[0]
            half = s.size[1] if len(s.size) > 1 else 0.0
            for z in (-half, half):
                for a in np.eye(3):
                    pts.extend((c + r @ (np.array([0, 0, z]) + radius * a),
                                c + r @ (np.array([0, 0, z]) - radius * a)))
    return np.array(pts) if pts else pos[i][None, :]


def find_limbs(tree: BodyTree) -> list[Limb]:
    """Every limb of ``tree`` (see the module docstring), in tree order."""
    pos, rot = tree.poses()
    torso = torso_links(tree)
    kids: dict[int, list[int]] = {}
    for i, link in enumerate(tree.links):
        kids.setdefault(link.parent, []).append(i)

    def subtree(i: int) -> list[int]:
        out = [i]
        for k in kids.get(i, []):
            out += subtree(k)
        return out

    limbs = []
    for start in (i for i in range(len(tree.links)) if i not in torso and tree.links[i].parent in torso):
        links = subtree(start)
        hinged = [i for i in links if tree.links[i].joint is not None]
        if not hinged:
            continue
        # the chain: the hinges on the way to the leaf that lies farthest from the start
        points = {i: link_points(tree, i, pos, rot) for i in links}
        far = {i: float(np.max(np.linalg.norm(points[i] - pos[start], axis=1))) for i in links}
        tip = max((i for i in links if not kids.get(i)), key=lambda i: far[i])
        chain = [i for i in tree.chain(tip) if i in links and tree.links[i].joint is not None]
        side = tuple(i for i in hinged if i not in chain)
        ends = np.concatenate([points[i] for i in subtree(chain[-1])])
        end = ends[int(np.argmax(np.linalg.norm(ends - pos[0], axis=1)))]
        limbs.append(Limb(tuple(chain), side, (float(end[0]), float(end[1]), float(end[2]))))
    return limbs


def side_of(tree: BodyTree, limb: Limb) -> str | None:
    """"l", "r" or None, by the names of the limb's links and hinges (most say which)."""
    names = [tree.links[i].name for i in limb.hinges]
    names += [tree.links[i].joint.name for i in limb.hinges if tree.links[i].joint]  # type: ignore[union-attr]
    left = sum(bool(LEFT.search(n)) for n in names)
    right = sum(bool(RIGHT.search(n)) for n in names)
    return "l" if left > right else "r" if right > left else None


def snap(v: Array, *, what: str, where: str, tol: float = SNAP_TOL) -> Array:
    """``v`` snapped to the nearest root axis (+-x, +-y, +-z); ConfigError if it is more
    than ``tol`` [rad] away."""
    u = np.asarray(v, float) / np.linalg.norm(v)
    k = int(np.argmax(np.abs(u)))
    axis = AXES[k] * np.sign(u[k])
    angle = float(np.arccos(np.clip(abs(u[k]), -1.0, 1.0)))
    if angle > tol:
        raise ConfigError(f"{where}: {what} is {np.degrees(angle):.2f} deg off the model's "
                          f"{'xyz'[k]} axis (found {np.round(u, 4).tolist()}); the importer needs "
                          f"it within {np.degrees(tol):.1f} deg of the model's root axes")
    return axis


def robot_axes(tree: BodyTree, legs: tuple[Limb, Limb]) -> Array:
    """The rotation from the model's root frame to the robot's (rows: forward, left, up in
    root coordinates); legs: (right, left)."""
    right, left = legs
    feet = 0.5 * (np.asarray(right.end) + np.asarray(left.end))
    pos, _ = tree.poses()
    up = snap(pos[0] - feet, what="up (from the feet to the torso)", where=tree.source,
              tol=ROUGH_TOL)
    hips = pos[left.hinges[0]] - pos[right.hinges[0]]
    across = hips - up * float(hips @ up)
    if np.linalg.norm(across) < 1e-6:
        raise ConfigError(f"{tree.source}: the two legs' hips are not side by side; cannot "
                          "tell left from right")
    lft = snap(across, what="left (from the right hip to the left one)", where=tree.source,
               tol=ROUGH_TOL)
    return np.array([np.cross(lft, up), lft, up])
