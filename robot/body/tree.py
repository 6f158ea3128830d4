"""A robot's body as data: links (rigid bodies) joined by hinges, each with its mass,
centre of mass, inertia, collision shapes and named frames.

One description, two sources: the box model built from a robot file's dozen lengths
(robot/body/boxes.py) and a builder's own URDF or MJCF (robot/body/urdf_read.py,
mjcf_read.py, through ``biped robots import``); robot/config/body_tree.py gives either
in the robot's terms. The simulation and ``biped mjcf`` build MuJoCo from it
(sim/mujoco/mjcf_body.py), and an imported robot's leg IK chains are measured on it
(robot/body/legs.py).

Frames: each link's frame is given relative to its parent's at the zero pose of every
joint (all hinge angles 0, in the model's own convention); the root link's frame is the
model's root frame. Units: m, kg, kg m^2, rad; quaternions are (w, x, y, z) as MuJoCo
writes them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import numpy.typing as npt

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]
Array = npt.NDArray[np.float64]

IDENTITY_QUAT: Quat = (1.0, 0.0, 0.0, 0.0)
ORIGIN: Vec3 = (0.0, 0.0, 0.0)
#: Shape kinds: MuJoCo's primitives, and a convex hull given by its vertices.
SHAPE_KINDS = ("box", "sphere", "capsule", "cylinder", "hull")


@dataclass(frozen=True)
class Inertial:
    """mass [kg]; com: centre of mass in the link frame [m]; inertia: (ixx, iyy, izz, ixy,
    ixz, iyz) about the centre of mass in the link's axes [kg m^2]."""

    mass: float
    com: Vec3
    inertia: tuple[float, float, float, float, float, float]

    def matrix(self) -> Array:
        ixx, iyy, izz, ixy, ixz, iyz = self.inertia
        return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


@dataclass(frozen=True)
class Shape:
    """A collision (or, for the box model, visual) shape fixed in its link.

    kind: one of SHAPE_KINDS; pos, quat: the shape frame in the link frame; size: MuJoCo's
    geom size (box: half sizes; sphere: radius; capsule and cylinder: radius and half
    length along the shape's z) [m]; vertices: a hull's vertices in the shape frame [m];
    visual: drawn only, never collides (the box model's servos and shells); material:
    the box model's colour name; note: where an imported shape came from and what was
    lost on the way (a mesh's hull, a stand-in box)."""

    kind: str
    pos: Vec3 = ORIGIN
    quat: Quat = IDENTITY_QUAT
    size: tuple[float, ...] = ()
    vertices: tuple[Vec3, ...] = ()
    name: str = ""
    visual: bool = False
    material: str = ""
    note: str = ""


@dataclass(frozen=True)
class Frame:
    """A named point and orientation on a link (a sole, the IMU, a hand) [m]."""

    name: str
    pos: Vec3 = ORIGIN
    quat: Quat = IDENTITY_QUAT


@dataclass(frozen=True)
class Hinge:
    """A revolute joint between a link and its parent, in the model's own terms.

    name: the model's joint name; axis: unit vector in the link frame; pos: a point of the
    axis in the link frame [m]; range: limits [rad] (None: the model gives none);
    effort [N m] and velocity [rad/s]: the model's limits, None where it gives none;
    ref: the angle at which the link stands as the tree draws it [rad] (0 in a model's
    own terms; a tree in the robot's terms, robot/body/model.py, moves the zero)."""

    name: str
    axis: Vec3
    pos: Vec3 = ORIGIN
    range: tuple[float, float] | None = None
    effort: float | None = None
    velocity: float | None = None
    ref: float = 0.0


@dataclass(frozen=True)
class Link:
    """A rigid body. parent: index of the parent link (-1: the root); pos, quat: the link
    frame in the parent's at the zero pose [m]; joint: the hinge to its parent (None:
    welded to it, or the root)."""

    name: str
    parent: int
    pos: Vec3 = ORIGIN
    quat: Quat = IDENTITY_QUAT
    inertial: Inertial | None = None
    joint: Hinge | None = None
    shapes: tuple[Shape, ...] = ()
    frames: tuple[Frame, ...] = ()


@dataclass(frozen=True)
class BodyTree:
    """links: parents before children, ``links[0]`` the root; source: where it was read;
    excludes: pairs of link names whose contacts the model turns off."""

    links: tuple[Link, ...]
    source: str = "<memory>"
    excludes: tuple[tuple[str, str], ...] = field(default=())

    @cached_property
    def index(self) -> dict[str, int]:
        """Link name → index."""
        return {link.name: i for i, link in enumerate(self.links)}

    @cached_property
    def joint_link(self) -> dict[str, int]:
        """Hinge name → index of the link it moves."""
        return {link.joint.name: i for i, link in enumerate(self.links) if link.joint}

    def children(self, i: int) -> list[int]:
        return [k for k, link in enumerate(self.links) if link.parent == i]

    def chain(self, i: int) -> list[int]:
        """The links from the root to link ``i``, both included."""
        out = [i]
        while self.links[out[-1]].parent >= 0:
            out.append(self.links[out[-1]].parent)
        return out[::-1]

    @property
    def mass(self) -> float:
        """Total mass [kg]."""
        return sum(link.inertial.mass for link in self.links if link.inertial)

    def poses(self, q: Mapping[str, float] | None = None) -> tuple[Array, Array]:
        """Every link frame in the root frame at hinge angles ``q`` [rad] (by hinge name;
        missing ones 0): positions (L, 3) [m] and rotations (L, 3, 3)."""
        angles = q or {}
        n = len(self.links)
        pos, rot = np.zeros((n, 3)), np.zeros((n, 3, 3))
        for i, link in enumerate(self.links):
            r_local = quat_to_matrix(link.quat)
            p_local = np.asarray(link.pos, float)
            if link.joint is not None:
                turn = axis_angle(link.joint.axis, angles.get(link.joint.name, 0.0))
                anchor = np.asarray(link.joint.pos, float)
                # the hinge turns the link about its axis through the anchor (link frame)
                p_local = p_local + r_local @ (anchor - turn @ anchor)
                r_local = r_local @ turn
            if link.parent < 0:
                pos[i], rot[i] = p_local, r_local
            else:
                pos[i] = pos[link.parent] + rot[link.parent] @ p_local
                rot[i] = rot[link.parent] @ r_local
        return pos, rot

    def poses_many(self, q: Mapping[str, Array], n: int) -> tuple[Array, Array]:
        """``poses`` over ``n`` frames at once: hinge angles ``q`` [rad] (n,) each, by
        hinge name (missing ones 0) → positions (L, n, 3) [m] and rotations (L, n, 3, 3)."""
        pos, rot = np.zeros((len(self.links), n, 3)), np.zeros((len(self.links), n, 3, 3))
        for i, link in enumerate(self.links):
            r_local = np.broadcast_to(quat_to_matrix(link.quat), (n, 3, 3))
            p_local = np.broadcast_to(np.asarray(link.pos, float), (n, 3))
            if link.joint is not None:
                a = np.asarray(link.joint.axis, float)
                a = a / np.linalg.norm(a)
                k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
                angle = np.broadcast_to(np.asarray(q.get(link.joint.name, 0.0), float), (n,))
                turn = (np.eye(3) + np.sin(angle)[:, None, None] * k
                        + (1.0 - np.cos(angle))[:, None, None] * (k @ k))
                anchor = np.asarray(link.joint.pos, float)
                p_local = p_local + np.einsum("nij,nj->ni", r_local, anchor - turn @ anchor)
                r_local = r_local @ turn
            if link.parent < 0:
                pos[i], rot[i] = p_local, r_local
            else:
                pos[i] = pos[link.parent] + np.einsum("nij,nj->ni", rot[link.parent], p_local)
                rot[i] = rot[link.parent] @ r_local
        return pos, rot


def quat_to_matrix(q: Quat | Array) -> Array:
    """Rotation matrix of the quaternion (w, x, y, z) (normalised first)."""
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def matrix_to_quat(r: Array) -> Quat:
    """The quaternion (w, x, y, z), w >= 0, of rotation matrix ``r`` (Shepperd's method)."""
    m = np.asarray(r, float)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    cands = (tr, m[0, 0], m[1, 1], m[2, 2])
    k = int(np.argmax(cands))
    if k == 0:
        s = 2.0 * np.sqrt(max(1.0 + tr, 0.0))
        q = (0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s)
    elif k == 1:
        s = 2.0 * np.sqrt(max(1.0 + m[0, 0] - m[1, 1] - m[2, 2], 0.0))
        q = ((m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s)
    elif k == 2:
        s = 2.0 * np.sqrt(max(1.0 + m[1, 1] - m[0, 0] - m[2, 2], 0.0))
        q = ((m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s)
    else:
        s = 2.0 * np.sqrt(max(1.0 + m[2, 2] - m[0, 0] - m[1, 1], 0.0))
        q = ((m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s)
    arr = np.asarray(q) / np.linalg.norm(q)
    if arr[0] < 0:
        arr = -arr
    return (float(arr[0]), float(arr[1]), float(arr[2]), float(arr[3]))


def axis_angle(axis: Vec3 | Array, angle: float) -> Array:
    """Rotation matrix turning ``angle`` [rad] about the unit vector ``axis`` (Rodrigues)."""
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def equivalent_box(inertial: Inertial, *, name: str = "", note: str = "") -> Shape:
    """The solid box of ``inertial``'s mass and principal moments, at its centre of mass
    in its principal axes (MuJoCo's equivalent-inertia box): half sizes
    sqrt(3 (I_j + I_k - I_i) / (2 m)) [m]."""
    moments, axes = np.linalg.eigh(inertial.matrix())
    if np.linalg.det(axes) < 0:
        axes[:, 0] = -axes[:, 0]
    m = inertial.mass
    total = float(moments.sum())
    half = tuple(float(np.sqrt(max(3.0 * (total - 2.0 * moments[i]) / (2.0 * m), 1e-12)))
                 for i in range(3))
    return Shape("box", inertial.com, matrix_to_quat(axes), half, name=name, note=note)
