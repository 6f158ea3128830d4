"""The simulated robot's feet: which geoms are soles, and where their points are.

A foot is every colliding geom named ``r_foot`` / ``l_foot``, or ``r_foot_N`` /
``l_foot_N`` (an imported foot of several shapes: sim/mujoco/mjcf_body.py names them so).
A geom's points are a box's corners, a mesh's vertices, or for the round shapes the ends of
their axes and radii; the sole of one geom is its points within ``SOLE_BAND`` of its
lowest one.
"""

from __future__ import annotations

import re

import mujoco
import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]
SIDES = ("r", "l")
#: A geom's points this close above its lowest one are on its sole [m].
SOLE_BAND = 0.002
_BOX = int(mujoco.mjtGeom.mjGEOM_BOX)
_MESH = int(mujoco.mjtGeom.mjGEOM_MESH)
_CORNERS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)


def foot_geoms(model: mujoco.MjModel) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """(right, left) sole geom ids; ValueError if a foot has none."""
    out = []
    for side in SIDES:
        pattern = re.compile(rf"{side}_foot(_\d+)?\Z")
        ids = tuple(g for g in range(model.ngeom) if pattern.match(model.geom(g).name or ""))
        if not ids:
            raise ValueError(f"the model has no foot geom named {side}_foot")
        out.append(ids)
    return out[0], out[1]


def geom_points(model: mujoco.MjModel, data: mujoco.MjData, g: int) -> Array:
    """Geom ``g``'s points in the world (n, 3) [m] (see the module docstring)."""
    rot = data.geom_xmat[g].reshape(3, 3)
    centre = data.geom_xpos[g]
    kind = int(model.geom_type[g])
    if kind == _BOX:
        local = _CORNERS * model.geom_size[g]
    elif kind == _MESH:
        mesh = int(model.geom_dataid[g])
        start, n = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
        local = np.asarray(model.mesh_vert[start:start + n], float)
    else:
        r = float(model.geom_size[g][0])
        half = float(model.geom_size[g][1]) if kind != int(mujoco.mjtGeom.mjGEOM_SPHERE) else 0.0
        local = np.array([[sx * r, sy * r, z] for z in (-half - r, half + r, -half, half)
                          for sx, sy in ((0, 0), (1, 0), (-1, 0), (0, 1), (0, -1))], float)
    return centre + local @ rot.T


def sole_points(model: mujoco.MjModel, data: mujoco.MjData, g: int) -> Array:
    """The points of geom ``g`` on its sole (world, (n, 3)) [m]."""
    pts = geom_points(model, data, g)
    return pts[pts[:, 2] <= pts[:, 2].min() + SOLE_BAND]
