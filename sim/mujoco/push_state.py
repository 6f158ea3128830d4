"""The body's state at the moment of a push, as the capture limit needs it
(robot.balance.capture_limit): the whole robot's centre of mass, its velocity, its height
over the ground, the mass, and per foot whether it touches the ground, where its ankle
is, where its hip holds it (``hip``: the point the ankle hangs under with every joint of
the model at 0, moved with the hip: forward with its pitch axis, sideways with its roll
axis, so that ankle - hip is the foot's step offset; on the box models the hip's anchor
itself, on the imported kits 2-7 cm from it) and the points of its sole geoms (a box's
corners).

Everything is in the torso's heading frame (its yaw only: x forward, y left, as the push
itself), horizontal, relative to the centre of mass's ground point; the height is over
the lowest sole point of the feet on the ground (of both feet when none is down);
``push_above_com_m``: how far above the whole robot's centre of mass the push acts (the
torso's own centre of mass, where the simulation applies it).
Read from MuJoCo (``mj_subtreeVel`` for the velocity), JSON-ready.
"""

from __future__ import annotations

import math
from typing import Any

import mujoco
import numpy as np

from sim.mujoco.geoms import foot_geoms, geom_points
from sim.mujoco.metrics import yaw_of

SIDES = ("r", "l")
ANKLES = {side: (f"{side}_ankle_pitch", f"{side}_ankle_roll") for side in SIDES}


def sole(model: mujoco.MjModel, data: mujoco.MjData, geoms: tuple[int, ...]) -> np.ndarray:
    """A foot's points in the world (n, 3) [m]: every point of its sole geoms
    (sim.mujoco.geoms.geom_points: a box's corners, a mesh's vertices), whose plan is the
    foot's print on the ground however it is tilted."""
    return np.concatenate([geom_points(model, data, g) for g in geoms])


def _anchor(model: mujoco.MjModel, data: mujoco.MjData, names: tuple[str, ...]) -> np.ndarray:
    """The world point of the first of the joints ``names`` the model has."""
    for name in names:
        if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) >= 0:
            return np.asarray(data.xanchor[model.joint(name).id])
    raise ValueError(f"the model has none of the joints {', '.join(names)}")


def _hip(model: mujoco.MjModel, data: mujoco.MjData, side: str) -> np.ndarray:
    """The hip's world (x, y): forward at the axis the leg swings forward and back about
    (its hip pitch), sideways at the one it swings out and in about (its hip roll); a
    joint's anchor is one point of its axis, defined across the axis only."""
    pitch = _anchor(model, data, (f"{side}_hip_pitch", f"{side}_hip_roll"))
    roll = _anchor(model, data, (f"{side}_hip_roll", f"{side}_hip_pitch"))
    return np.array([pitch[0], roll[1]])


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
    zero = mujoco.MjData(model)       # every joint at 0: where each ankle hangs
    mujoco.mj_kinematics(model, zero)
    feet, lowest, soles = [], [], []
    for side, geoms, down in zip(SIDES, foot_geoms(model), touching, strict=True):
        points = sole(model, data, geoms)
        soles.append(float(points[:, 2].min()))
        if down:
            lowest.append(soles[-1])
        ankle = _anchor(model, data, ANKLES[side])
        # the hip's offset over its ankle at the zero pose, in the torso's frame (qpos0:
        # the torso unturned), taken off in the heading frame
        ox, oy = _hip(model, zero, side) - _anchor(model, zero, ANKLES[side])[:2]
        x, y = rot @ (_hip(model, data, side) - com[:2]) - (ox, oy)
        feet.append({"down": bool(down), "ankle": local(ankle), "hip": [float(x), float(y)],
                     "sole": [local(p) for p in points]})
    lowest = lowest or soles
    v = rot @ vel[:2]
    torso = float(data.xipos[root][2])        # the push's point: the torso's own centre
    return {"com_height_m": float(com[2] - min(lowest)),
            "push_above_com_m": torso - float(com[2]),
            "com_velocity_m_s": [float(v[0]), float(v[1])],
            "mass_kg": float(model.body_subtreemass[root]),
            "yaw_rad": yaw, "feet": feet}
