"""What the simulated bus lets a test or a metric see of the robot's body: the torso's pose,
its tilt, the feet's ground contact, and offscreen frames (a mixin of
``sim.mujoco.bus.MujocoBus``, which provides the model, the data, the ground and foot
geoms and the renderer once open)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import numpy.typing as npt

from sim.mujoco.geoms import sole_points
from sim.mujoco.view import OffscreenRenderer


class BodyObservation:
    """Read-only views of the simulated body (world frame, SI units)."""

    _ground: npt.NDArray[np.intp]
    _feet: tuple[tuple[int, ...], tuple[int, ...]]  # (right, left) sole geoms
    _renderer: OffscreenRenderer

    @property
    def model(self) -> mujoco.MjModel:
        raise NotImplementedError

    @property
    def data(self) -> mujoco.MjData:
        raise NotImplementedError


    def base_pose(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """Torso (pelvis frame) position [m] and orientation quaternion (w, x, y, z)."""
        q = self.data.qpos
        return q[0:3].copy(), q[3:7].copy()

    def upright_angle(self) -> float:
        """Angle between the torso's z axis and world z [rad] (0 upright, pi/2 lying)."""
        _, x, y, _ = self.data.qpos[3:7]
        qn = float(np.dot(self.data.qpos[3:7], self.data.qpos[3:7]))
        return math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (x * x + y * y) / qn)))

    def contacts_feet(self) -> tuple[bool, bool]:
        """(right, left): is each foot box touching the ground (floor or a bump; as of the
        last step)."""
        d = self.data
        pairs = d.contact.geom[: d.ncon]
        ground = np.isin(pairs, self._ground)
        touching = []
        for foot in self._feet:
            mine = np.isin(pairs, foot)
            hit = (mine[:, 0] & ground[:, 1]) | (mine[:, 1] & ground[:, 0])
            touching.append(bool(hit.any()))
        return touching[0], touching[1]

    def sole_corners(self) -> list[npt.NDArray[np.float64]]:
        """World points (n, 3) [m] of the sole of each foot that touches the ground (as of
        the last step; a box's four bottom corners): the support polygon's points."""
        out = []
        for foot, on in zip(self._feet, self.contacts_feet(), strict=True):
            if on:
                out.append(np.concatenate([sole_points(self.model, self.data, g) for g in foot]))
        return out

    def render(self, width: int, height: int, camera: str = "track") -> npt.NDArray[np.uint8]:
        """An offscreen RGB frame (height, width, 3) of the current state (needs MUJOCO_GL
        set, e.g. egl, before mujoco is imported). Reuses one renderer per size."""
        return self._renderer.render(self.model, self.data, width, height, camera)
