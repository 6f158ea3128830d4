"""The robot's MJCF around its bodies (sim/mujoco/mjcf_body.py writes those): the default
classes (the robot's, and the visual, collision and contact classes), the materials, the
actuators and the IMU sensors; each joint and actuator carries its own servo's parameters
(``servo_attributes``). The same for every robot, box model or imported.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from robot.config.robot import RobotConfig
from sim.mujoco.servo_law import robot_servos

#: Collision bits: floor/world 1, right leg 2, left leg 4. Legs collide with the floor and
#: the other leg; torso and arms only with the floor (never parent-child, never same leg).
CONTACT = {"r_leg": ("2", "5"), "l_leg": ("4", "3"), "body": ("0", "1")}
#: Materials (the box model's shapes name them; an imported body's shapes get them by place).
MATERIALS = {"shell": "0.85 0.85 0.8 1", "servo": "0.1 0.1 0.1 1", "link": "0.55 0.6 0.65 1",
             "foot": "0.9 0.45 0.1 1"}


def servo_attributes(robot: RobotConfig) -> dict[str, tuple[dict[str, str], dict[str, str]]]:
    """Per joint name: (joint attributes, actuator attributes) of its servo with the torque
    on (``sim.mujoco.servo_law``: the firmware law at the robot's gains and voltage, the
    motor's back-EMF and the gearbox as damping, frictionloss and armature)."""
    a = robot_servos(robot)
    out = {}
    for i, j in enumerate(robot.joints):
        joint = {"armature": num(a.armature[i]), "damping": num(a.viscous[i] + a.back_emf[i]),
                 "frictionloss": num(a.coulomb[i] + a.stribeck[i])}
        act = {"kp": num(a.kp[i]), "kv": num(a.kv[i]),
               "forcerange": num(-a.force[i], a.force[i])}
        out[j.name] = (joint, act)
    return out


def fmt(*values: float) -> str:
    """Floats as exact shortest round-trip strings (FK tests compare to 1e-9 m)."""
    return " ".join(repr(float(v)) for v in values)


def num(*values: float) -> str:
    """Physical parameters to 6 significant digits (readability over round-trip)."""
    return " ".join(f"{v:.6g}" for v in values)


def sub(parent: ET.Element, tag: str, **attrs: str) -> ET.Element:
    return ET.SubElement(parent, tag, {k.rstrip("_"): v for k, v in attrs.items() if v})


def add_defaults(root: ET.Element, robot: RobotConfig, *, drawn: bool) -> None:
    """The robot's class (geom friction and contact stiffness, sites), the ``visual`` class
    (drawn, never collides, no mass), the ``collision`` class and one contact class per
    group under it (CONTACT). ``drawn``: the body has no visual shapes, so its collision
    shapes are what is drawn (grey, group 2); else they are hidden (group 3, translucent)."""
    default = sub(root, "default")
    top = sub(default, "default", class_=robot.name)
    sub(top, "geom", friction="1 0.005 0.0001", solref="0.005 1",
        rgba="0.6 0.6 0.6 1" if drawn else "")
    sub(top, "site", group="5", size="0.005", rgba="1 0.2 0.2 1")
    visual = sub(top, "default", class_="visual")
    sub(visual, "geom", contype="0", conaffinity="0", group="2", density="0")
    collision = sub(top, "default", class_="collision")
    sub(collision, "geom", group="2" if drawn else "3", rgba="" if drawn else "0.6 0.2 0.2 0.5")
    for name, (contype, conaffinity) in CONTACT.items():
        group = sub(collision, "default", class_=name)
        sub(group, "geom", contype=contype, conaffinity=conaffinity)


def add_actuators_and_sensors(root: ET.Element, robot: RobotConfig) -> None:
    """Position actuators named after their joints, with each servo's law and the joint's
    limits as ctrlrange; each joint gets its servo's damping, frictionloss and armature
    (``servo_attributes``)."""
    act = sub(root, "actuator")
    servo = servo_attributes(robot)
    for joint in root.iter("joint"):
        if joint.get("name") in servo:
            joint.attrib.update(servo[joint.attrib["name"]][0])
    for j in robot.joints:
        sub(act, "position", name=j.name, joint=j.name, ctrlrange=fmt(j.min_rad, j.max_rad),
            **servo[j.name][1])
    sensors = sub(root, "sensor")
    sub(sensors, "gyro", name="imu_gyro", site="imu")
    sub(sensors, "accelerometer", name="imu_accelerometer", site="imu")
    sub(sensors, "framequat", name="imu_orientation", objtype="site", objname="imu")


def add_assets(root: ET.Element) -> None:
    assets = sub(root, "asset")
    for name, rgba in MATERIALS.items():
        sub(assets, "material", name=name, rgba=rgba)
