"""An imported robot's own body (robot/body/model.py) as the MJCF body tree the simulation
runs: the model's links with their masses, centres of mass, inertias, joint frames and
collision shapes, in the project's terms.

- The root link becomes the ``torso`` body, re-expressed in the pelvis frame (the robot's
  REP-103 axes, origin midway between the hips), so every sim feature that reads the
  torso (odometry, heading, the IMU, pushes) sees the same frame as on a box model.
- Each hinge is named after the project's joint and turns the project's way: its axis is
  ``model_sign`` times the model's and its ``ref`` is ``-model_sign * model_offset``, so
  qpos is the project's angle and the bodies stand as the model draws them at the model's
  zero. The joint range is the robot file's limits.
- The servo law (sim/mujoco/servo_law.py) is written on every joint and actuator, as for
  the box model; the model's own actuators, damping and friction are not used.
- Collision shapes: primitives as they are; a hull as a mesh given by its vertices (MuJoCo
  collides a mesh by its hull). The foot's shapes are ``r_foot``, ``r_foot_1``...
  (sim/mujoco/geoms.py); legs collide with the floor and the other leg, the rest with the
  floor only (as sim/mujoco/mjcf_robot.py's CONTACT). Every shape is also drawn.
- The model's frames become sites; ``r_sole``, ``l_sole`` and ``imu`` are the importer's.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from robot.body.tree import BodyTree, Shape, matrix_to_quat, quat_to_matrix
from robot.config.robot import RobotConfig
from sim.mujoco.mjcf_robot import CONTACT, _sub, fmt, servo_attributes

FOOT_ROLES = ("ankle_roll", "ankle_pitch")
HIP_ROLES = ("hip_yaw", "hip_roll")


def _subtree(tree: BodyTree, i: int) -> set[int]:
    return {k for k in range(len(tree.links)) if i in tree.chain(k)}


def _first_link(robot: RobotConfig, side: str, roles: tuple[str, ...], *, nearest: bool
                ) -> int | None:
    """Of the links moved by ``roles`` on ``side``, the one nearest the torso (the leg's
    start) or, ``nearest`` False, the farthest (the foot)."""
    assert robot.body is not None
    tree = robot.body.tree
    links = [tree.joint_link[j.model_joint] for j in robot.joints
             if j.name in {f"{side}_{r}" for r in roles} and j.model_joint]
    if not links:
        return None
    depth = {i: len(tree.chain(i)) for i in links}
    return min(links, key=depth.__getitem__) if nearest else max(links, key=depth.__getitem__)


def add_body_worldbody(root: ET.Element, robot: RobotConfig, height0: float) -> list[str]:
    """The ``worldbody`` of ``robot``'s own body (``robot.body``), its torso ``height0`` [m]
    above the floor; adds the hull meshes to ``<asset>``. Returns the joint names in qpos
    order."""
    body = robot.body
    assert body is not None
    tree = body.tree
    r_pel, p_pel = body.root_to_pelvis()
    by_model = {j.model_joint: j for j in robot.joints}
    leg_of: dict[int, str] = {}
    foot_of: dict[int, str] = {}
    for side in "rl":
        start = _first_link(robot, side, HIP_ROLES + ("hip_pitch",), nearest=True)
        foot = _first_link(robot, side, FOOT_ROLES, nearest=False)
        for i in _subtree(tree, start) if start is not None else ():
            leg_of[i] = f"{side}_leg"
        for i in _subtree(tree, foot) if foot is not None else ():
            foot_of[i] = side
    assets = root.find("asset")
    assert assets is not None
    feet_count = {"r": 0, "l": 0}
    names = {i: ("torso" if i == 0 else (link.name if link.name != "torso" else "torso_link"))
             for i, link in enumerate(tree.links)}
    elements: dict[int, ET.Element] = {}
    order: list[str] = []
    world = _sub(root, "worldbody")
    for i, link in enumerate(tree.links):
        if i == 0:
            el = _sub(world, "body", name="torso", pos=fmt(0, 0, height0), childclass=robot.name)
            _sub(el, "freejoint", name="root")
            turn, move = r_pel, lambda v: r_pel @ (np.asarray(v, float) - p_pel)
        else:
            parent = elements[link.parent]
            if link.parent == 0:
                pos = r_pel @ (np.asarray(link.pos) - p_pel)
                quat = matrix_to_quat(r_pel @ quat_to_matrix(link.quat))
            else:
                pos, quat = np.asarray(link.pos), link.quat
            el = _sub(parent, "body", name=names[i], pos=fmt(*pos), quat=fmt(*quat))
            turn, move = np.eye(3), lambda v: np.asarray(v, float)
        elements[i] = el
        if link.inertial is not None:
            inert = link.inertial
            full = turn @ inert.matrix() @ turn.T
            _sub(el, "inertial", pos=fmt(*move(inert.com)), mass=fmt(inert.mass),
                 fullinertia=fmt(full[0, 0], full[1, 1], full[2, 2], full[0, 1], full[0, 2],
                                 full[1, 2]))
        if link.joint is not None:
            j = by_model[link.joint.name]
            axis = np.asarray(link.joint.axis, float) * j.model_sign
            _sub(el, "joint", name=j.name, axis=fmt(*axis), pos=fmt(*link.joint.pos),
                 range=fmt(j.min_rad, j.max_rad), ref=fmt(-j.model_sign * j.model_offset))
            order.append(j.name)
        contact = leg_of.get(i, "body")
        for k, shape in enumerate(link.shapes):
            gname = ""
            if i in foot_of:
                side = foot_of[i]
                gname = f"{side}_foot" if feet_count[side] == 0 else f"{side}_foot_{feet_count[side]}"
                feet_count[side] += 1
            _shape(el, assets, shape, contact, gname, f"{names[i]}_{k}", turn, move)
        for f in link.frames:
            rot = turn @ quat_to_matrix(f.quat)
            _sub(el, "site", name=f.name, pos=fmt(*move(f.pos)), quat=fmt(*matrix_to_quat(rot)))
    excl = [(names[tree.index[a]], names[tree.index[b]]) for a, b in tree.excludes]
    if excl:
        contact_el = _sub(root, "contact")
        for a, b in excl:
            _sub(contact_el, "exclude", body1=a, body2=b)
    return order


def _shape(el: ET.Element, assets: ET.Element, shape: Shape, contact: str, name: str,
           mesh_name: str, turn: np.ndarray, move: object) -> None:
    pos = move(shape.pos)  # type: ignore[operator]
    quat = matrix_to_quat(turn @ quat_to_matrix(shape.quat))
    material = "foot" if name else "link" if contact != "body" else "shell"
    attrs = {"pos": fmt(*pos), "quat": fmt(*quat), "material": material, "group": "2"}
    if shape.kind == "hull":
        _sub(assets, "mesh", name=mesh_name, vertex=fmt(*np.ravel(shape.vertices)))
        _sub(el, "geom", name=name, class_=contact, type="mesh", mesh=mesh_name, **attrs)
    else:
        _sub(el, "geom", name=name, class_=contact, type=shape.kind, size=fmt(*shape.size), **attrs)


def add_body_actuators(root: ET.Element, robot: RobotConfig) -> None:
    """Position actuators named after their joints with each servo's law (explicit
    ctrlrange: the imported body's joints use no default classes), and the IMU sensors."""
    servo = servo_attributes(robot)
    for joint in root.iter("joint"):
        if joint.get("name") in servo:
            joint.attrib.update(servo[joint.attrib["name"]][0])
    act = _sub(root, "actuator")
    for j in robot.joints:
        _sub(act, "position", name=j.name, joint=j.name, ctrlrange=fmt(j.min_rad, j.max_rad),
             **servo[j.name][1])
    sensors = _sub(root, "sensor")
    _sub(sensors, "gyro", name="imu_gyro", site="imu")
    _sub(sensors, "accelerometer", name="imu_accelerometer", site="imu")
    _sub(sensors, "framequat", name="imu_orientation", objtype="site", objname="imu")


def add_body_defaults(root: ET.Element, robot: RobotConfig) -> None:
    """The defaults an imported body uses: the robot's class (geom friction and contact
    stiffness as the box model's) and one contact class per group (CONTACT)."""
    default = _sub(root, "default")
    top = _sub(default, "default", class_=robot.name)
    _sub(top, "geom", friction="1 0.005 0.0001", solref="0.005 1", rgba="0.6 0.6 0.6 1")
    _sub(top, "site", group="5", size="0.005", rgba="1 0.2 0.2 1")
    for name, (contype, conaffinity) in CONTACT.items():
        sub = _sub(top, "default", class_=name)
        _sub(sub, "geom", contype=contype, conaffinity=conaffinity)
