"""The body's state at the moment of a push, as the capture limit needs it
(robot.balance.capture_limit): the whole robot's centre of mass, its velocity, its height
over the ground, the mass, and per foot whether it touches the ground, where its ankle
and hip are and the corners of its sole.

Everything is in the torso's heading frame (its yaw only: x forward, y left, as the push
itself), horizontal, relative to the centre of mass's ground point; the height is over
the lowest sole corner of the feet on the ground (of both feet when none is down);
``push_above_com_m``: how far above the whole robot's centre of mass the push acts (the
torso's own centre of mass, where the simulation applies it).
Read from MuJoCo (``mj_subtreeVel`` for the velocity), JSON-ready.
"""

from __future__ import annotations

import math
from typing import Any

import mujoco
import numpy as np

from sim.mujoco.metrics import yaw_of
from sim.mujoco.mjcf import FOOT_GEOMS

SIDES = ("r", "l")


def sole_corners(model: mujoco.MjModel, data: mujoco.MjData, geom: int) -> np.ndarray:
    """The world corners (4, 3) [m] of a box sole's bottom face."""
    sx, sy, sz = model.geom_size[geom]
    local = np.array([[x, y, -sz] for x in (-sx, sx) for y in (-sy, sy)])
    return data.geom_xpos[geom] + local @ data.geom_xmat[geom].reshape(3, 3).T


def body_state(model: mujoco.MjModel, data: mujoco.MjData,
               touching: tuple[bool, bool]) -> dict[str, Any]:
    """The state now (module doc); ``touching``: (right, left) foot on the ground."""
    mujoco.mj_subtreeVel(model, data)
    root = model.body("torso").id
    com = np.array(data.subtree_com[root])
    vel = np.array(data.subtree_linvel[root])
    yaw = yaw_of(data.qpos[3:7])
    c, s = math.cos(yaw), math.sin(yaw)
    rot = np.array([[c, s], [-s, c]])                   # world -> heading frame

    def local(p: np.ndarray) -> list[float]:
        x, y = rot @ (np.asarray(p[:2]) - com[:2])
        return [float(x), float(y)]
    feet, lowest = [], []
    for side, geom_name, down in zip(SIDES, FOOT_GEOMS, touching, strict=True):
        corners = sole_corners(model, data, model.geom(geom_name).id)
        if down:
            lowest.append(float(corners[:, 2].min()))
        feet.append({"down": bool(down),
                     "ankle": local(data.xanchor[model.joint(f"{side}_ankle_pitch").id]),
                     "hip": local(data.xanchor[model.joint(f"{side}_hip_roll").id]),
                     "sole": [local(p) for p in corners]})
    if not lowest:
        lowest = [float(min(sole_corners(model, data, model.geom(n).id)[:, 2].min()
                            for n in FOOT_GEOMS))]
    v = rot @ vel[:2]
    torso = float(data.xipos[root][2])        # the push's point: the torso's own centre
    return {"com_height_m": float(com[2] - min(lowest)),
            "push_above_com_m": torso - float(com[2]),
            "com_velocity_m_s": [float(v[0]), float(v[1])],
            "mass_kg": float(model.body_subtreemass[root]),
            "yaw_rad": yaw, "feet": feet}
