"""Rigid-body inertia arithmetic on ``Inertial`` (robot/body/tree.py): principal moments and
axes, an inertial seen from another frame, two inertials combined (the parallel axis
theorem), the sides and density of the equivalent-inertia box (the box itself as a shape:
robot.body.tree.equivalent_box), a solid sphere's inertial.

Units: kg, m, kg m^2; the density of the equivalent box in kg/m^3.
"""

from __future__ import annotations

import math

import numpy as np

from robot.body.tree import ORIGIN, Array, Inertial

ZERO_INERTIA = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def from_matrix(mass: float, com: Array | tuple[float, ...], matrix: Array) -> Inertial:
    """An Inertial of ``mass`` [kg] at ``com`` [m] with the 3x3 inertia ``matrix`` about the
    centre of mass [kg m^2] (symmetrised)."""
    m = 0.5 * (np.asarray(matrix, float) + np.asarray(matrix, float).T)
    c = np.asarray(com, float)
    return Inertial(mass=float(mass), com=(float(c[0]), float(c[1]), float(c[2])),
                    inertia=(float(m[0, 0]), float(m[1, 1]), float(m[2, 2]),
                             float(m[0, 1]), float(m[0, 2]), float(m[1, 2])))


def principal(inertial: Inertial) -> tuple[Array, Array]:
    """Principal moments, ascending [kg m^2], and the rotation whose columns are their axes
    (right-handed) in the inertial's frame."""
    moments, axes = np.linalg.eigh(inertial.matrix())
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    return moments, axes


def transformed(inertial: Inertial, pos: Array, rot: Array) -> Inertial:
    """``inertial`` of a frame placed at ``pos`` [m], turned by ``rot``, in the outer frame."""
    r = np.asarray(rot, float)
    com = np.asarray(pos, float) + r @ np.asarray(inertial.com, float)
    return from_matrix(inertial.mass, com, r @ inertial.matrix() @ r.T)


def _about(point: Array, mass: float, com: Array) -> Array:
    """The parallel-axis term: a point mass at ``com`` seen from ``point``."""
    d = com - point
    return mass * (float(d @ d) * np.eye(3) - np.outer(d, d))


def combined(a: Inertial | None, b: Inertial | None) -> Inertial | None:
    """The inertial of two bodies welded together (both in one frame): masses added, the
    centre of mass their weighted mean, inertias moved to it (parallel axis theorem)."""
    if a is None or b is None:
        return b if a is None else a
    mass = a.mass + b.mass
    ca, cb = np.asarray(a.com, float), np.asarray(b.com, float)
    if mass <= 0.0:
        return from_matrix(mass, ca, a.matrix() + b.matrix())
    com = (a.mass * ca + b.mass * cb) / mass
    matrix = a.matrix() + _about(com, a.mass, ca) + b.matrix() + _about(com, b.mass, cb)
    return from_matrix(mass, com, matrix)


def box_sides(inertial: Inertial) -> tuple[Array, Array]:
    """Full side lengths [m] of the equivalent-inertia box along the principal axes (a
    solid box: I_x = m (b^2 + c^2) / 12 and so on, so a^2 = 6 (I_y + I_z - I_x) / m), and
    those axes (columns). Sides of moments breaking the triangle inequality are 0."""
    moments, axes = principal(inertial)
    ix, iy, iz = moments
    squares = 6.0 * np.array([iy + iz - ix, ix + iz - iy, ix + iy - iz]) / inertial.mass
    return np.sqrt(np.maximum(squares, 0.0)), axes


def box_density(inertial: Inertial) -> float:
    """Mass over the volume of the equivalent-inertia box [kg/m^3] (inf for a flat box)."""
    sides, _ = box_sides(inertial)
    volume = float(np.prod(sides))
    return inertial.mass / volume if volume > 0.0 else math.inf


def sphere_inertial(mass: float, com: tuple[float, float, float] = ORIGIN, *,
                    density: float) -> Inertial:
    """A uniform solid sphere of ``mass`` [kg] and ``density`` [kg/m^3] at ``com``."""
    radius = (3.0 * mass / (4.0 * math.pi * density)) ** (1.0 / 3.0)
    moment = 0.4 * mass * radius * radius
    return Inertial(mass=mass, com=com, inertia=(moment, moment, moment, 0.0, 0.0, 0.0))
