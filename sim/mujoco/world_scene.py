"""A ``sim.mujoco.world.World`` applied to the MuJoCo scene: the tilted floor and the bumps (MJCF),
friction and mass (the compiled model), the robot's start pose on the slope (the data).

Each function changes nothing for a field at its default, so ``World()`` leaves the model
exactly as without a world.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import mujoco
import numpy as np
import numpy.typing as npt

from sim.mujoco.mjcf_robot import fmt
from sim.mujoco.world import World
from sim.mujoco.world_stairs import stair_boxes

#: Bump field in the floor frame: x from BUMPS_X0_M to BUMPS_X0_M + BUMPS_LENGTH_M (ahead
#: of the start pose's toes), |y| <= BUMPS_HALF_WIDTH_M [m].
BUMPS_X0_M = 0.1
BUMPS_LENGTH_M = 5.0
BUMPS_HALF_WIDTH_M = 0.5
BUMP_CELL_M = 0.1  # the field is cut into square cells; at most one box per cell [m]
BUMP_SIDE_M = (0.03, 0.08)  # each side of a box: uniform in this range [m]
BUMP_COVER = 0.25  # expected share of the field's area under a box
BUMP_PREFIX = "bump"
BUMP_RGBA = "0.55 0.45 0.35 1"
STAIR_PREFIX = "stair"
STAIR_RGBA = "0.5 0.55 0.6 1"
MM = 1e-3  # [m/mm]


@dataclass(frozen=True)
class Bump:
    """A box on the floor: centre (x, y) in the floor frame and full sides [m]."""

    x: float
    y: float
    size_x: float
    size_y: float


def bump_layout(seed: int) -> list[Bump]:
    """The boxes for ``seed`` (independent of their height): each cell gets a box with
    probability BUMP_COVER * cell^2 / E[side]^2, placed at random inside its cell."""
    rng = np.random.default_rng(seed)
    lo, hi = BUMP_SIDE_M
    mean_side = (lo + hi) / 2
    chance = BUMP_COVER * BUMP_CELL_M ** 2 / mean_side ** 2
    nx = round(BUMPS_LENGTH_M / BUMP_CELL_M)
    ny = round(2 * BUMPS_HALF_WIDTH_M / BUMP_CELL_M)
    bumps = []
    for i in range(nx):
        for j in range(ny):
            present, sx, sy, fx, fy = rng.random(5)
            if present >= chance:
                continue
            size_x, size_y = lo + (hi - lo) * sx, lo + (hi - lo) * sy
            x = BUMPS_X0_M + i * BUMP_CELL_M + size_x / 2 + fx * (BUMP_CELL_M - size_x)
            y = -BUMPS_HALF_WIDTH_M + j * BUMP_CELL_M + size_y / 2 + fy * (BUMP_CELL_M - size_y)
            bumps.append(Bump(x, y, size_x, size_y))
    return bumps


def _rotate(quat: tuple[float, float, float, float],
            v: tuple[float, float, float]) -> npt.NDArray[np.float64]:
    out = np.zeros(3)
    mujoco.mju_rotVecQuat(out, np.asarray(v, float), np.asarray(quat, float))
    return out


def add_world_to_scene(worldbody: ET.Element, floor: ET.Element, world: World) -> None:
    """Tilt ``floor`` and add the bump boxes and the stairs (static geoms colliding like
    the floor)."""
    quat = world.floor_quat()
    if world.tilted:
        floor.set("quat", fmt(*quat))

    def box(name: str, centre: tuple[float, float, float],
            half: tuple[float, float, float], rgba: str) -> None:
        attrs = {"name": name, "type": "box", "pos": fmt(*_rotate(quat, centre)),
                 "size": fmt(*half), "rgba": rgba, "contype": "1", "conaffinity": "1"}
        if world.tilted:
            attrs["quat"] = fmt(*quat)
        ET.SubElement(worldbody, "geom", attrs)

    for k, s in enumerate(stair_boxes(world.stairs_height_m, world.stairs_count,
                                          world.stairs_tread_m)):
        box(f"{STAIR_PREFIX}{k}", s.centre, s.half_sides, STAIR_RGBA)
    if world.bumps_mm <= 0.0:
        return
    half_h = world.bumps_mm * MM / 2
    for k, b in enumerate(bump_layout(world.terrain_seed)):
        box(f"{BUMP_PREFIX}{k}", (b.x, b.y, half_h), (b.size_x / 2, b.size_y / 2, half_h),
            BUMP_RGBA)


def apply_world_to_model(model: mujoco.MjModel, data: mujoco.MjData, world: World) -> None:
    """Friction and mass scales on the compiled model (then its derived constants)."""
    if world.friction_scale != 1.0:
        model.geom_friction[:, 0] *= world.friction_scale
    if world.mass_scale != 1.0:
        robot = np.arange(1, model.nbody)  # every body but the world
        model.body_mass[robot] *= world.mass_scale
        model.body_inertia[robot] *= world.mass_scale
        mujoco.mj_setConst(model, data)


def place_on_floor(data: mujoco.MjData, world: World) -> None:
    """Rotate the free-floating robot (qpos[0:7]) rigidly about the origin with the floor,
    so soles resting on z = 0 rest on the tilted plane through the origin."""
    if not world.tilted:
        return
    quat = np.asarray(world.floor_quat(), float)
    pos = data.qpos[0:3].copy()
    body = data.qpos[3:7].copy()
    mujoco.mju_rotVecQuat(data.qpos[0:3], pos, quat)
    mujoco.mju_mulQuat(data.qpos[3:7], quat, body)

