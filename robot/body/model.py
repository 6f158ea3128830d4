"""An imported robot's own body, as its robot file carries it: the body tree in the
model's terms, how the robot's frame sits in the model's root frame, and the legs as the
IK solves them (robot/body/legs.py).

The joints' names and conventions in the model (``model_joint``, ``model_sign``,
``model_offset``: model angle = model_sign * angle + model_offset) live on each joint of
the robot file (robot/config/robot.py ``JointConfig``), next to its servo.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robot.body.legs import LegChain
from robot.body.tree import Array, BodyTree, Vec3


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
