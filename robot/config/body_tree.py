"""The body a robot file describes, in the robot's terms: one body tree (robot/body/tree.py)
whichever the source, for the simulation and ``biped mjcf`` (sim/mujoco/mjcf_body.py) to
build.

- A hand-written robot file: the box model (robot/body/boxes.py) from its ``[geometry]``,
  ``[mass]``, the bus's servo, its joints' limits and its extra joints' layout
  (robot/config/extra_joints.py).
- An imported one: its ``[model]`` (robot/body/model.py ``BodyModel.robot_tree``), each
  hinge named, signed and zeroed as its joint's ``model_joint``, ``model_sign`` and
  ``model_offset`` say.

Either way the root link's frame is the pelvis frame and the hinges carry the project's
joint names, directions and the robot file's limits.
"""

from __future__ import annotations

from robot.body.boxes import ExtraLink, box_tree
from robot.body.model import JointTerms
from robot.body.tree import BodyTree
from robot.config.extra_joints import UNIT, extra_layout, link_length
from robot.config.robot import RobotConfig
from robot.errors import ConfigError


def robot_tree(robot: RobotConfig) -> BodyTree:
    """``robot``'s body tree in the robot's terms (module docstring)."""
    limits = {j.name: (j.min_rad, j.max_rad) for j in robot.joints}
    if robot.body is not None:
        return robot.body.robot_tree({
            j.model_joint: JointTerms(j.name, j.model_sign, j.model_offset, limits[j.name])
            for j in robot.joints if j.model_joint})
    if robot.mass is None:
        raise ConfigError(f"{robot.source}: the box model needs [mass] (or an imported "
                          "[model])")
    link = link_length(robot)
    extras = [ExtraLink(e.name, UNIT[e.axis], e.parent, e.offset, e.kind, link)
              for e in extra_layout(robot)]
    return box_tree(robot.geometry, robot.mass, servo_mass=robot.bus.servo.mass,
                    joints=limits, extras=extras, source=robot.source)


def stand_height(robot: RobotConfig) -> float:
    """How high the pelvis stands above the floor with the robot's joints at zero and its
    soles on the floor [m]: the straight box leg, or an imported robot's lowest sole."""
    if robot.body is None:
        g = robot.geometry
        return g.thigh + g.shin + g.ankle_height
    return -min(leg.zero_sole()[2] for leg in robot.body.legs)
