"""The oracle of tests/test_box_body.py: the box robot's MJCF exactly as
sim/mujoco/mjcf_robot.py wrote it straight from a robot file before the box model became a
body tree (commit 8f95a8c, issue 31): default classes for the joint groups, capsules by
``fromto``, ``diaginertia`` boxes, written element by element from ``Geometry`` and
``Masses``. It shares with the code under test only the inputs (the robot file, the
extra joints' layout), the servo law (sim/mujoco/mjcf_robot.py ``servo_attributes``) and
the scene; the body, the classes, the inertials, the shapes and the sites are this file's
own.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import numpy.typing as npt

from robot.config.extra_joints import UNIT, extra_axis, extra_layout, link_length
from robot.config.joint_names import JOINT_NAMES
from robot.config.robot import RobotConfig
from sim.mujoco.mjcf_robot import servo_attributes

AXES = {"hip_yaw": "0 0 1", "hip_roll": "1 0 0", "hip_pitch": "0 1 0", "knee": "0 1 0",
        "ankle_pitch": "0 1 0", "ankle_roll": "1 0 0", "shoulder_pitch": "0 1 0",
        "shoulder_roll": "1 0 0", "elbow": "0 1 0"}
SIDE_Y = {"r": -1.0, "l": 1.0}
#: Extra joints (head pan, tilt, jaw, tail): placed and turned as robot/config/extra_joints.py
#: lays them out; each a small servo with a visible link (a head on the last of a neck chain).
EXTRA_MASS_KG = 0.02
#: Collision bits: floor/world 1, right leg 2, left leg 4. Legs collide with the floor and
#: the other leg; torso and arms only with the floor (never parent-child, never same leg).
CONTACT = {"r_leg": ("2", "5"), "l_leg": ("4", "3"), "body": ("0", "1")}
SERVO_DENSITY = 1500.0  # [kg/m^3], a servo's average density (sets link thickness)


def fmt(*values: float) -> str:
    """Floats as exact shortest round-trip strings (FK tests compare to 1e-9 m)."""
    return " ".join(repr(float(v)) for v in values)


def _sub(parent: ET.Element, tag: str, **attrs: str) -> ET.Element:
    return ET.SubElement(parent, tag, {k.rstrip("_"): v for k, v in attrs.items() if v})


def joint_class(robot: RobotConfig, name: str) -> str:
    """Default class of joint ``name``: its group ("knee"), or per side if the sides differ
    (limits or servo model); an extra joint (head_pan) has its own."""
    if name not in JOINT_NAMES:
        return name
    group = name[2:]
    other = robot.joint(("l_" if name.startswith("r_") else "r_") + group)
    mine = robot.joint(name)
    same = ((mine.min_rad, mine.max_rad, robot.servo(mine).name)
            == (other.min_rad, other.max_rad, robot.servo(other).name))
    return group if same else name


def add_defaults(root: ET.Element, robot: RobotConfig) -> None:
    default = _sub(root, "default")
    top = _sub(default, "default", class_=robot.name)
    _sub(top, "geom", friction="1 0.005 0.0001", solref="0.005 1")
    _sub(top, "site", group="5", size="0.005", rgba="1 0.2 0.2 1")
    models: dict[str, ET.Element] = {}   # one class per servo model (a robot may mix them)
    done: set[str] = set()
    for j in robot.joints:
        servo = robot.servo(j)
        if servo.name not in models:
            models[servo.name] = _sub(top, "default", class_=servo.name)
        cls = joint_class(robot, j.name)
        if cls in done:
            continue
        done.add(cls)
        group = _sub(models[servo.name], "default", class_=cls)
        axis = AXES[j.name[2:]] if j.name in JOINT_NAMES else fmt(*UNIT[extra_axis(j.name)])
        _sub(group, "joint", axis=axis,
             range=fmt(j.min_rad, j.max_rad))
        _sub(group, "position", ctrlrange=fmt(j.min_rad, j.max_rad))
    visual = _sub(top, "default", class_="visual")
    _sub(visual, "geom", contype="0", conaffinity="0", group="2", density="0")
    collision = _sub(top, "default", class_="collision")
    _sub(collision, "geom", group="3", rgba="0.6 0.2 0.2 0.5")
    for name, (contype, conaffinity) in CONTACT.items():
        sub = _sub(collision, "default", class_=name)
        _sub(sub, "geom", contype=contype, conaffinity=conaffinity)


def _inertial(body: ET.Element, mass: float, centre: tuple[float, float, float],
              size: tuple[float, float, float]) -> None:
    """A solid box of full ``size`` [m] and ``mass`` [kg] centred at ``centre``."""
    a, b, c = size
    inertia = (mass * (b * b + c * c) / 12, mass * (a * a + c * c) / 12,
               mass * (a * a + b * b) / 12)
    _sub(body, "inertial", pos=fmt(*centre), mass=fmt(mass), diaginertia=fmt(*inertia))


def _body(parent: ET.Element, name: str, pos: tuple[float, float, float],
          joint: str | None, robot: RobotConfig) -> ET.Element:
    body = _sub(parent, "body", name=name, pos=fmt(*pos))
    if joint is not None and joint in robot.joint_names:   # 5-DoF legs: no hip yaw joint
        _sub(body, "joint", name=joint, class_=joint_class(robot, joint))
    return body


def add_worldbody(root: ET.Element, robot: RobotConfig) -> None:
    g, m = robot.geometry, robot.mass
    assert m is not None, "the box model needs [mass]"
    s = (robot.bus.servo.mass / SERVO_DENSITY) ** (1 / 3)  # servo edge [m]
    r = 0.45 * s  # link capsule radius [m]
    world = _sub(root, "worldbody")
    height0 = g.thigh + g.shin + g.ankle_height  # qpos0: straight legs, soles at z=0
    torso = _sub(world, "body", name="torso", pos=fmt(0, 0, height0), childclass=robot.name)
    _sub(torso, "freejoint", name="root")
    width = max(g.hip_width + s, g.shoulder_width - 1.6 * s)
    bottom, top = 0.6 * s, g.torso_height + 0.4 * s
    tsize = (g.torso_depth, width, top - bottom)
    tcentre = (0.0, 0.0, (bottom + top) / 2)
    _inertial(torso, m.torso, tcentre, tsize)
    for cls in ("visual", "body"):
        _sub(torso, "geom", name="torso" if cls == "body" else "torso_visual", class_=cls,
             type="box", pos=fmt(*tcentre), size=fmt(*(x / 2 for x in tsize)),
             material="shell")
    _sub(torso, "site", name="imu", pos=fmt(*tcentre))
    servo_box = fmt(s / 2, s / 2, s / 2)
    for side in ("r", "l"):
        y = SIDE_Y[side]
        leg = f"{side}_leg"
        b = _body(torso, f"{side}_hip_yaw_link", (0, y * g.hip_width / 2, 0),
                  f"{side}_hip_yaw", robot)
        if m.hip_yaw_link:                  # 5-DoF legs: no hip yaw servo, a massless frame
            _inertial(b, m.hip_yaw_link, (0, 0, 0.5 * s), (s, s, s))
            _sub(b, "geom", class_="visual", type="box", pos=fmt(0, 0, 0.5 * s),
                 size=servo_box, material="servo")
        b = _body(b, f"{side}_hip_roll_link", (0, 0, 0), f"{side}_hip_roll", robot)
        _inertial(b, m.hip_roll_link, (0, 0, 0), (s, s, s))
        _sub(b, "geom", class_="visual", type="box", size=servo_box, material="servo")
        b = _body(b, f"{side}_thigh", (0, 0, 0), f"{side}_hip_pitch", robot)
        _inertial(b, m.thigh, (0, 0, -g.thigh / 2), (s, s, g.thigh))
        for cls, gname in (("visual", ""), (leg, f"{side}_thigh")):
            _sub(b, "geom", name=gname, class_=cls, type="capsule", size=fmt(r),
                 fromto=fmt(0, 0, 0, 0, 0, -g.thigh), material="link")
        b = _body(b, f"{side}_shin", (0, 0, -g.thigh), f"{side}_knee", robot)
        _inertial(b, m.shin, (0, 0, -g.shin / 2), (s, s, g.shin))
        _sub(b, "geom", class_="visual", type="box", size=servo_box, material="servo")
        for cls, gname in (("visual", ""), (leg, f"{side}_shin")):
            _sub(b, "geom", name=gname, class_=cls, type="capsule", size=fmt(r),
                 fromto=fmt(0, 0, 0, 0, 0, -g.shin), material="link")
        b = _body(b, f"{side}_ankle_link", (0, 0, -g.shin), f"{side}_ankle_pitch", robot)
        _inertial(b, m.ankle_link, (0, 0, 0), (s, s, s))
        _sub(b, "geom", class_="visual", type="box", size=servo_box, material="servo")
        b = _body(b, f"{side}_foot", (0, 0, 0), f"{side}_ankle_roll", robot)
        fsize = (g.foot_length, g.foot_width, g.ankle_height)
        fcentre = (g.foot_forward, 0.0, -g.ankle_height / 2)
        _inertial(b, m.foot, fcentre, fsize)
        half = fmt(g.foot_length / 2, g.foot_width / 2, g.ankle_height / 4)
        plate = fmt(g.foot_forward, 0, -0.75 * g.ankle_height)
        _sub(b, "geom", name=f"{side}_foot", class_=leg, type="box", pos=plate, size=half)
        _sub(b, "geom", class_="visual", type="box", pos=plate, size=half, material="foot")
        _sub(b, "site", name=f"{side}_sole", pos=fmt(0, 0, -g.ankle_height))
    if not robot.has_arms:
        add_extra_joints(torso, robot, s)   # after the legs and arms: robot.joints order
        return
    for side in ("r", "l"):
        y = SIDE_Y[side]
        b = _body(torso, f"{side}_shoulder_link", (0, y * g.shoulder_width / 2, g.torso_height),
                  f"{side}_shoulder_pitch", robot)
        _inertial(b, m.shoulder_link, (0, 0, 0), (s, s, s))
        _sub(b, "geom", class_="visual", type="box", size=servo_box, material="servo")
        b = _body(b, f"{side}_upper_arm", (0, 0, 0), f"{side}_shoulder_roll", robot)
        _inertial(b, m.upper_arm, (0, 0, -g.upper_arm / 2), (s, s, g.upper_arm))
        for cls in ("visual", "body"):
            _sub(b, "geom", class_=cls, type="capsule", size=fmt(0.8 * r),
                 fromto=fmt(0, 0, 0, 0, 0, -g.upper_arm), material="link")
        b = _body(b, f"{side}_forearm", (0, 0, -g.upper_arm), f"{side}_elbow", robot)
        _inertial(b, m.forearm, (0, 0, -g.forearm / 2), (s, s, g.forearm))
        _sub(b, "geom", class_="visual", type="box", size=servo_box, material="servo")
        for cls in ("visual", "body"):
            _sub(b, "geom", class_=cls, type="capsule", size=fmt(0.8 * r),
                 fromto=fmt(0, 0, 0, 0, 0, -g.forearm), material="link")
        _sub(b, "site", name=f"{side}_hand", pos=fmt(0, 0, -g.forearm))
    add_extra_joints(torso, robot, s)


def add_extra_joints(torso: ET.Element, robot: RobotConfig, s: float) -> None:
    """One small body per extra joint on top of the torso. Added after the legs and arms,
    so qpos and the actuators follow ``robot.joints`` order."""
    link = link_length(robot)
    bodies: dict[str, ET.Element] = {}
    for e in extra_layout(robot):
        parent = bodies[e.parent] if e.parent else torso
        b = bodies[e.name] = _body(parent, f"{e.name}_link", e.offset, e.name, robot)
        _inertial(b, EXTRA_MASS_KG, (0, 0, 0), (s / 2, s / 2, s / 2))
        _sub(b, "geom", class_="visual", type="box", size=fmt(s / 2, s / 2, s / 2),
             material="servo")
        if e.kind == "head":
            _sub(b, "geom", class_="visual", type="box", size=fmt(link, 0.9 * link, 0.8 * link),
                 pos=fmt(0, 0, link), material="shell")
        elif e.kind == "jaw":
            _sub(b, "geom", class_="visual", type="box", size=fmt(0.6 * link, 0.7 * link,
                                                                  0.15 * link),
                 pos=fmt(0.5 * link, 0, -0.2 * link), material="link")
        elif e.kind == "tail":
            _sub(b, "geom", class_="visual", type="capsule", size=fmt(0.3 * s),
                 fromto=fmt(0, 0, 0, -link, 0, 0), material="link")


def add_actuators_and_sensors(root: ET.Element, robot: RobotConfig) -> None:
    """Position actuators named after their joints, with each servo's law; each joint gets
    its servo's damping, frictionloss and armature (``servo_attributes``)."""
    act = _sub(root, "actuator")
    servo = servo_attributes(robot)
    for joint in root.iter("joint"):
        if joint.get("name") in servo:   # the bodies' joints, not the defaults' templates
            joint.attrib.update(servo[joint.attrib["name"]][0])
    for j in robot.joints:
        _sub(act, "position", name=j.name, joint=j.name, class_=joint_class(robot, j.name),
             **servo[j.name][1])
    sensors = _sub(root, "sensor")
    _sub(sensors, "gyro", name="imu_gyro", site="imu")
    _sub(sensors, "accelerometer", name="imu_accelerometer", site="imu")
    _sub(sensors, "framequat", name="imu_orientation", objtype="site", objname="imu")


def add_assets(root: ET.Element) -> None:
    assets = _sub(root, "asset")
    for name, rgba in (("shell", "0.85 0.85 0.8 1"), ("servo", "0.1 0.1 0.1 1"),
                       ("link", "0.55 0.6 0.65 1"), ("foot", "0.9 0.45 0.1 1")):
        _sub(assets, "material", name=name, rgba=rgba)


def robot_xml(robot: RobotConfig, *, home: npt.NDArray[np.float64] | None = None,
              ctrl: npt.NDArray[np.float64] | None = None, timestep: float = 0.002) -> str:
    """The box robot's robot.xml as it was written (sim/mujoco/mjcf.py's box branch)."""
    root = ET.Element("mujoco", model=robot.name)
    ET.SubElement(root, "compiler", angle="radian", autolimits="true")
    ET.SubElement(root, "option", timestep=fmt(timestep), integrator="implicitfast")
    add_defaults(root, robot)
    add_assets(root)
    add_worldbody(root, robot)
    add_actuators_and_sensors(root, robot)
    if home is not None:
        keyframe = ET.SubElement(root, "keyframe")
        ET.SubElement(keyframe, "key", name="home", qpos=fmt(*home),
                      ctrl=fmt(*(home[7:] if ctrl is None else ctrl)))
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"
