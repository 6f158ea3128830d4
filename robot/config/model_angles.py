"""An imported robot's joint angles in its model's own terms: each joint under the name the
model file gives its hinge (``model_joint``), in the file's convention (model angle =
``model_sign`` * angle + ``model_offset``: the value MuJoCo's qpos or a URDF tool's joint
state takes). ``biped curves --model-angles``, ``--record ... --model-names``, the panel's
state and the previs skeleton of an imported robot read joint angles through this.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from robot.config.robot import RobotConfig
from robot.errors import ConfigError

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class ModelAngles:
    """joints: the project's names, in the robot file's order; names: the model's name of
    each; sign (+1/-1) and offset [rad] of each: model angle = sign * angle + offset."""

    joints: tuple[str, ...]
    names: tuple[str, ...]
    sign: tuple[float, ...]
    offset: tuple[float, ...]

    @staticmethod
    def of(robot: RobotConfig, *, what: str = "the model's joint names") -> ModelAngles:
        """The robot's model angles; ConfigError (one line, naming ``what`` asked for
        them) for a robot with no model (a box robot, written by hand)."""
        if robot.body is None:
            raise ConfigError(f"{what}: {robot.name} ({robot.source}) has no model (a box "
                              "robot written by hand has no model file's joint names); "
                              "give a robot made by `biped robots import`")
        names = []
        for j in robot.joints:
            if j.model_joint is None:   # robot_file's check_model_joints refuses this
                raise ConfigError(f"{robot.source}: joints.{j.name}.model_joint: missing")
            names.append(j.model_joint)
        return ModelAngles(robot.joint_names, tuple(names),
                           tuple(float(j.model_sign) for j in robot.joints),
                           tuple(float(j.model_offset) for j in robot.joints))

    def values(self, q: npt.ArrayLike) -> Array:
        """Model angles [rad] of the project's angles ``q`` (..., joints) [rad]."""
        return (np.asarray(self.sign) * np.asarray(q, dtype=float)
                + np.asarray(self.offset))

    def named(self, q: npt.ArrayLike) -> dict[str, Array]:
        """Model angles [rad] by model joint name, of ``q`` (..., joints) [rad]: each an
        array of ``q``'s leading shape."""
        v = self.values(q)
        return {name: v[..., k] for k, name in enumerate(self.names)}

    def zero(self) -> dict[str, float]:
        """The model angles of the project's zero pose (legs straight, feet flat) [rad]."""
        return dict(zip(self.names, self.offset, strict=True))
