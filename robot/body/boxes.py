"""The box model as a body tree: a hand-written robot file's dozen lengths and masses
(robot/config/robot.py ``Geometry`` and ``Masses``) become links of solid boxes, joined
by hinges whose axes are the pelvis frame's x, y or z (REP-103, right-hand rule).

The chain is the one ``Geometry`` documents: every link frame parallel to the pelvis
frame at the zero pose (the root link's frame is the pelvis frame), the three hip axes
meeting at the hip centre, the two ankle axes at the ankle. Each link's mass is a solid
box sized by the geometry and the servo's edge (a servo of ``servo_mass`` at
``SERVO_DENSITY``); a link with no mass (5-DoF legs: no hip yaw servo) is a bare frame.
Collision shapes: the torso box, the thigh and shin capsules, the foot plate (and the
arms' capsules); visual shapes: the servos, the shells, the links and the foot, each with
its material. Frames: ``imu`` at the torso's centre, ``r_sole`` / ``l_sole`` under the
ankles, ``r_hand`` / ``l_hand`` at the ends of the forearms.

This module takes plain numbers (robot/body does not read robot files):
robot/config/body_tree.py passes a robot file's in. Units: m, kg, rad.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

from robot.body.tree import ORIGIN, BodyTree, Frame, Hinge, Inertial, Link, Shape, Vec3

#: Each joint's axis in the pelvis frame, by its part of the limb.
AXES: dict[str, Vec3] = {
    "hip_yaw": (0.0, 0.0, 1.0), "hip_roll": (1.0, 0.0, 0.0), "hip_pitch": (0.0, 1.0, 0.0),
    "knee": (0.0, 1.0, 0.0), "ankle_pitch": (0.0, 1.0, 0.0), "ankle_roll": (1.0, 0.0, 0.0),
    "shoulder_pitch": (0.0, 1.0, 0.0), "shoulder_roll": (1.0, 0.0, 0.0),
    "elbow": (0.0, 1.0, 0.0)}
SIDE_Y = {"r": -1.0, "l": 1.0}
#: A quarter turn about y (a capsule's axis along x): the tail, as MuJoCo turns a capsule
#: given ``fromto`` along x (cos and sin of pi/4, w first).
TAIL_QUAT = (math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0)
#: An extra joint's link (head pan, tilt, jaw, tail): a small servo [kg].
EXTRA_MASS_KG = 0.02
#: A servo's average density [kg/m^3]: sets the servo's edge, hence the links' thickness.
SERVO_DENSITY = 1500.0


class BoxGeometry(Protocol):
    """The lengths the box model is drawn from [m] (robot/config/robot.py ``Geometry``)."""

    @property
    def hip_width(self) -> float: ...
    @property
    def thigh(self) -> float: ...
    @property
    def shin(self) -> float: ...
    @property
    def ankle_height(self) -> float: ...
    @property
    def foot_length(self) -> float: ...
    @property
    def foot_width(self) -> float: ...
    @property
    def foot_forward(self) -> float: ...
    @property
    def torso_height(self) -> float: ...
    @property
    def torso_depth(self) -> float: ...
    @property
    def shoulder_width(self) -> float: ...
    @property
    def upper_arm(self) -> float: ...
    @property
    def forearm(self) -> float: ...


class BoxMasses(Protocol):
    """The links' masses [kg] (robot/config/robot.py ``Masses``)."""

    @property
    def torso(self) -> float: ...
    @property
    def hip_yaw_link(self) -> float: ...
    @property
    def hip_roll_link(self) -> float: ...
    @property
    def thigh(self) -> float: ...
    @property
    def shin(self) -> float: ...
    @property
    def ankle_link(self) -> float: ...
    @property
    def foot(self) -> float: ...
    @property
    def shoulder_link(self) -> float: ...
    @property
    def upper_arm(self) -> float: ...
    @property
    def forearm(self) -> float: ...


@dataclass(frozen=True)
class ExtraLink:
    """An extra joint's link (robot/config/extra_joints.py lays them out): name (the
    joint's); axis: unit vector in the pelvis frame; parent: the extra joint it sits on
    (None: the torso); offset: from the parent's frame [m]; kind: "neck", "head", "jaw"
    or "tail" (what is drawn); link: the spacing of the chain's joints [m]."""

    name: str
    axis: Vec3
    parent: str | None
    offset: Vec3
    kind: str
    link: float


def solid_box(mass: float, centre: Vec3, size: Vec3) -> Inertial:
    """A solid box of ``mass`` [kg] and full ``size`` [m] centred at ``centre``."""
    a, b, c = size
    return Inertial(mass, centre, (mass * (b * b + c * c) / 12, mass * (a * a + c * c) / 12,
                                   mass * (a * a + b * b) / 12, 0.0, 0.0, 0.0))


def _down(length: float, radius: float, *, name: str = "", visual: bool = False) -> Shape:
    """A capsule of ``radius`` from the link's origin to ``length`` below it [m]."""
    return Shape("capsule", (0.0, 0.0, -length / 2), size=(radius, length / 2), name=name,
                 visual=visual, material="link")


def _servo(half: float, pos: Vec3 = ORIGIN) -> Shape:
    return Shape("box", pos, size=(half, half, half), visual=True, material="servo")


class _Builder:
    def __init__(self, joints: Mapping[str, tuple[float, float]]) -> None:
        self.joints = joints
        self.links: list[Link] = []

    def add(self, name: str, parent: str | None, pos: Vec3, joint: str | None,
            inertial: Inertial | None, shapes: Sequence[Shape] = (),
            frames: Sequence[Frame] = (), *, axis: Vec3 | None = None) -> None:
        """A link; its hinge only if the robot has ``joint`` (5-DoF legs: no hip yaw)."""
        hinge = None
        if joint is not None and joint in self.joints:
            hinge = Hinge(joint, axis or AXES[joint[2:]], range=self.joints[joint])
        index = -1 if parent is None else [k.name for k in self.links].index(parent)
        self.links.append(Link(name, index, pos, inertial=inertial, joint=hinge,
                               shapes=tuple(shapes), frames=tuple(frames)))


def box_tree(g: BoxGeometry, m: BoxMasses, *, servo_mass: float,
             joints: Mapping[str, tuple[float, float]], extras: Sequence[ExtraLink] = (),
             source: str = "<memory>") -> BodyTree:
    """The box model's links (module docstring). ``servo_mass``: the bus's servo [kg];
    ``joints``: the robot's joints and their limits [rad], by name (legs, arms if it has
    them, extras); ``extras``: the extra joints' links, in the robot's joint order."""
    s = (servo_mass / SERVO_DENSITY) ** (1 / 3)   # servo edge [m]
    r = 0.45 * s                                   # link capsule radius [m]
    b = _Builder(joints)
    width = max(g.hip_width + s, g.shoulder_width - 1.6 * s)
    bottom, top = 0.6 * s, g.torso_height + 0.4 * s
    tsize = (g.torso_depth, width, top - bottom)
    tcentre = (0.0, 0.0, (bottom + top) / 2)
    thalf = (tsize[0] / 2, tsize[1] / 2, tsize[2] / 2)
    b.add("torso", None, ORIGIN, None, solid_box(m.torso, tcentre, tsize),
          (Shape("box", tcentre, size=thalf, name="torso_visual", visual=True, material="shell"),
           Shape("box", tcentre, size=thalf, name="torso", material="shell")),
          (Frame("imu", tcentre),))
    cube = (s, s, s)
    for side in ("r", "l"):
        y = SIDE_Y[side]
        yaw = solid_box(m.hip_yaw_link, (0.0, 0.0, 0.5 * s), cube) if m.hip_yaw_link else None
        b.add(f"{side}_hip_yaw_link", "torso", (0.0, y * g.hip_width / 2, 0.0),
              f"{side}_hip_yaw", yaw, (_servo(s / 2, (0.0, 0.0, 0.5 * s)),) if yaw else ())
        b.add(f"{side}_hip_roll_link", f"{side}_hip_yaw_link", ORIGIN, f"{side}_hip_roll",
              solid_box(m.hip_roll_link, ORIGIN, cube), (_servo(s / 2),))
        b.add(f"{side}_thigh", f"{side}_hip_roll_link", ORIGIN, f"{side}_hip_pitch",
              solid_box(m.thigh, (0.0, 0.0, -g.thigh / 2), (s, s, g.thigh)),
              (_down(g.thigh, r, visual=True), _down(g.thigh, r, name=f"{side}_thigh")))
        b.add(f"{side}_shin", f"{side}_thigh", (0.0, 0.0, -g.thigh), f"{side}_knee",
              solid_box(m.shin, (0.0, 0.0, -g.shin / 2), (s, s, g.shin)),
              (_servo(s / 2), _down(g.shin, r, visual=True),
               _down(g.shin, r, name=f"{side}_shin")))
        b.add(f"{side}_ankle_link", f"{side}_shin", (0.0, 0.0, -g.shin), f"{side}_ankle_pitch",
              solid_box(m.ankle_link, ORIGIN, cube), (_servo(s / 2),))
        plate = (g.foot_forward, 0.0, -0.75 * g.ankle_height)
        half = (g.foot_length / 2, g.foot_width / 2, g.ankle_height / 4)
        b.add(f"{side}_foot", f"{side}_ankle_link", ORIGIN, f"{side}_ankle_roll",
              solid_box(m.foot, (g.foot_forward, 0.0, -g.ankle_height / 2),
                        (g.foot_length, g.foot_width, g.ankle_height)),
              (Shape("box", plate, size=half, name=f"{side}_foot"),
               Shape("box", plate, size=half, visual=True, material="foot")),
              (Frame(f"{side}_sole", (0.0, 0.0, -g.ankle_height)),))
    if "r_shoulder_pitch" in joints:     # arms: all their joints or none
        for side in ("r", "l"):
            _arm(b, g, m, side, s, 0.8 * r)
    for e in extras:
        _extra(b, e, s)
    return BodyTree(tuple(b.links), source=source)


def _arm(b: _Builder, g: BoxGeometry, m: BoxMasses, side: str, s: float, r: float) -> None:
    b.add(f"{side}_shoulder_link", "torso",
          (0.0, SIDE_Y[side] * g.shoulder_width / 2, g.torso_height), f"{side}_shoulder_pitch",
          solid_box(m.shoulder_link, ORIGIN, (s, s, s)), (_servo(s / 2),))
    b.add(f"{side}_upper_arm", f"{side}_shoulder_link", ORIGIN, f"{side}_shoulder_roll",
          solid_box(m.upper_arm, (0.0, 0.0, -g.upper_arm / 2), (s, s, g.upper_arm)),
          (_down(g.upper_arm, r, visual=True), _down(g.upper_arm, r)))
    b.add(f"{side}_forearm", f"{side}_upper_arm", (0.0, 0.0, -g.upper_arm), f"{side}_elbow",
          solid_box(m.forearm, (0.0, 0.0, -g.forearm / 2), (s, s, g.forearm)),
          (_servo(s / 2), _down(g.forearm, r, visual=True), _down(g.forearm, r)),
          (Frame(f"{side}_hand", (0.0, 0.0, -g.forearm)),))


def _extra(b: _Builder, e: ExtraLink, s: float) -> None:
    """One small servo link per extra joint, and what its kind draws."""
    link = e.link
    shapes = [_servo(s / 2)]
    if e.kind == "head":
        shapes.append(Shape("box", (0.0, 0.0, link), size=(link, 0.9 * link, 0.8 * link),
                            visual=True, material="shell"))
    elif e.kind == "jaw":
        shapes.append(Shape("box", (0.5 * link, 0.0, -0.2 * link),
                            size=(0.6 * link, 0.7 * link, 0.15 * link), visual=True,
                            material="link"))
    elif e.kind == "tail":   # from the joint back along -x
        shapes.append(Shape("capsule", (-link / 2, 0.0, 0.0), TAIL_QUAT, (0.3 * s, link / 2),
                            visual=True, material="link"))
    parent = f"{e.parent}_link" if e.parent else "torso"
    b.add(f"{e.name}_link", parent, e.offset, e.name,
          solid_box(EXTRA_MASS_KG, ORIGIN, (s / 2, s / 2, s / 2)), shapes, axis=e.axis)
