"""Which model joint is which of the project's joints, its sign, and the offset between
the model's zero and the project's zero pose (legs straight and hanging, feet flat, arms
hanging: docs/robots.md).

A joint's role comes from its axis in the robot frame (robot/body/limbs.py) and its place
in its limb. Working from the torso outward, each joint's offset is chosen so the next
part hangs as the zero pose says, and the axes are read at that corrected pose:

- leg: hip yaw (about z) turns the leg until the next axis (roll) lies along x; hip roll
  (x) until the pitch axis lies along y (or, roll first, the yaw axis along z); hip pitch
  and knee (y) until the knee, then the ankle, hang straight below; ankle pitch (y) and
  ankle roll (x) until the sole (the lowest face of the foot's shapes) is level;
- arm: shoulder pitch (y) and roll (x) until the upper arm hangs straight down; the
  elbow (the third joint) keeps the model's zero;
- every other joint (a neck, a head, antennas, a tail) is an extra joint at the model's
  zero.

Leg patterns taken (axes torso outward): z x y y y x (6-DoF), x y y y x (no hip yaw),
z x y y y and x z y y y (no ankle roll, roll before yaw in the second). A joint's ``sign``
is +1 where its axis points along the project's axis (REP-103, right-hand rule), -1
against; its angle in the model's terms is ``sign * angle + offset``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from robot.body.limbs import SNAP_TOL, Limb, find_limbs, robot_axes, side_of
from robot.body.pose import Pose, sole_normal
from robot.body.tree import Array, BodyTree
from robot.errors import ConfigError

X, Y, Z = np.eye(3)
LEG_PATTERNS = {"zxyyyx": ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll"),
                "xyyyx": ("hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll"),
                "zxyyy": ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch"),
                "xzyyy": ("hip_roll", "hip_yaw", "hip_pitch", "knee", "ankle_pitch")}
ARM_ROLES = ("shoulder_pitch", "shoulder_roll", "elbow")
#: A sole point counts as on the sole within this height of the lowest one [m].
SOLE_BAND = 0.002


@dataclass(frozen=True)
class JointRole:
    """model_joint: the model's name; name: the project's (r_knee, head_pan...); sign,
    offset [rad]: model angle = sign * angle + offset; link: the link it moves."""

    model_joint: str
    name: str
    sign: int
    offset: float
    link: int


@dataclass(frozen=True)
class Roles:
    """axes: the robot frame's x, y, z as rows in the model's root frame; joints: the
    project's order (right leg, left leg, right arm, left arm, extras); legs and arms:
    (right, left); order: "yaw_roll" or "roll_yaw"."""

    axes: Array
    joints: tuple[JointRole, ...]
    legs: tuple[Limb, Limb]
    arms: tuple[Limb, Limb] | None
    order: str

    def by_name(self) -> dict[str, JointRole]:
        return {j.name: j for j in self.joints}

    def model_angles(self, q: Mapping[str, float] | None = None) -> dict[str, float]:
        """Model joint angles [rad] for the project's angles ``q`` (missing ones 0)."""
        angles = q or {}
        return {j.model_joint: j.sign * angles.get(j.name, 0.0) + j.offset for j in self.joints}


def extra_name(model_joint: str) -> str:
    """A model's joint name as an extra joint's name (lowercase letters, digits, '_')."""
    name = re.sub(r"[^a-z0-9_]+", "_", model_joint.lower()).strip("_") or "joint"
    return (name if name[0].isalpha() else f"j_{name}")[:32]


def _letter(v: Array) -> str:
    k = int(np.argmax(np.abs(v)))
    return "xyz"[k] if math.acos(min(abs(float(v[k])) / float(np.linalg.norm(v)), 1.0)) <= SNAP_TOL else "?"


def _angle_to(v: Array, about: Array, target: Array) -> float:
    """The turn about ``about`` [rad] that brings ``v`` (projected on the plane normal to
    ``about``) onto ``target``'s direction in that plane."""
    a = v - about * float(v @ about)
    b = target - about * float(target @ about)
    if np.linalg.norm(a) < 1e-9:
        return 0.0
    return math.atan2(float(np.cross(a, b) @ about), float(a @ b))


def _leg_roles(pose: Pose, limb: Limb, side: str, feet: list[int]) -> tuple[list[JointRole], str]:
    tree = pose.tree
    hinges = list(limb.hinges)
    names = [tree.links[i].joint.name for i in hinges]  # type: ignore[union-attr]
    pattern = ""
    out: list[JointRole] = []
    for k, link in enumerate(hinges):
        letter = _letter(pose.axis(link))
        pattern += letter
        nxt = hinges[k + 1] if k + 1 < len(hinges) else None
        ys_before = pattern.count("y")
        if letter in "xz" and nxt is not None and ys_before == 0:  # hip yaw or roll
            about = Z if letter == "z" else X
            nax = pose.axis(nxt)
            others = [a for a in (X, Y, Z) if a is not about]
            target = max(others, key=lambda a: abs(float(nax @ a)))
            pose.turn(link, about, _angle_to(nax, about, target * (1.0 if nax @ target >= 0 else -1.0)))
        elif letter == "y" and ys_before <= 2:           # hip pitch, knee: hang straight
            below = hinges[k + 1]
            v = pose.anchor(below) - pose.anchor(link)
            pose.turn(link, Y, _angle_to(v, Y, -Z))
        elif letter == "y" and nxt is not None:          # ankle pitch: the roll axis along x
            nax = pose.axis(nxt)
            pose.turn(link, Y, _angle_to(nax, Y, X * (1.0 if nax @ X >= 0 else -1.0)))
        elif letter == "y":                              # ankle pitch: sole level in pitch
            pose.turn(link, Y, _angle_to(sole_normal(pose, feet), Y, -Z))
        elif letter == "x":                              # ankle roll: sole level in roll
            pose.turn(link, X, _angle_to(sole_normal(pose, feet), X, -Z))
    roles = LEG_PATTERNS.get(pattern)
    most = {"z": 1, "x": 2, "y": 3}
    for letter, n in most.items():
        found = [name for name, a in zip(names, pattern, strict=True) if a == letter]
        if roles is None and len(found) > n:
            what = {"z": "hip yaw", "x": "roll (hip and ankle)", "y": "pitch (hip, knee, ankle)"}
            raise ConfigError(f"{tree.source}: leg {names[0]}..{names[-1]}: {len(found)} joints "
                              f"turn about {letter} ({', '.join(found)}): more than the "
                              f"{n} {what[letter]} a leg has, so two would take one role; "
                              "name the joints with --map")
    if roles is None:
        raise ConfigError(f"{tree.source}: leg {names[0]}..{names[-1]}: axes {pattern} (torso "
                          f"outward, at the zero pose); the importer takes "
                          f"{', '.join(LEG_PATTERNS)} (hip yaw z, roll x, pitch y, knee y, ankle "
                          "pitch y, roll x); name the joints with --map")
    for link, role in zip(hinges, roles, strict=True):
        axis = {"hip_yaw": Z, "hip_roll": X, "ankle_roll": X}.get(role, Y)
        hinge = tree.links[link].joint
        assert hinge is not None
        sign = 1 if float(pose.axis(link) @ axis) > 0 else -1
        out.append(JointRole(hinge.name, f"{side}_{role}", sign,
                             _wrap(pose.angles.get(hinge.name, 0.0)), link))
    order = "roll_yaw" if pattern.startswith("xz") else "yaw_roll"
    return out, order


def _wrap(a: float) -> float:
    return math.atan2(math.sin(a), math.cos(a))


def _arm_roles(pose: Pose, limb: Limb, side: str) -> list[JointRole]:
    tree = pose.tree
    hinges = list(limb.hinges)
    upper_end = pose.anchor(hinges[2])
    for link, about in zip(hinges[:2], (Y, X), strict=True):
        if _letter(pose.axis(link)) != "xyz"[int(np.argmax(about))]:
            hinge = tree.links[link].joint
            raise ConfigError(f"{tree.source}: arm joint {hinge.name!r}: turns about "  # type: ignore[union-attr]
                              f"{_letter(pose.axis(link))}; the importer expects shoulder pitch "
                              "(y), then roll (x), then the elbow; name the joints with --map")
        upper_end = pose.anchor(hinges[2])
        v = upper_end - pose.anchor(hinges[1])
        if np.linalg.norm(v - about * float(v @ about)) > 1e-6:
            pose.turn(link, about, _angle_to(v, about, -Z))
    out = []
    elbow_axis = pose.axis(hinges[2])
    lateral = _letter(elbow_axis) == "x"
    for link, role in zip(hinges, ARM_ROLES, strict=True):
        axis = {"shoulder_pitch": Y, "shoulder_roll": X}.get(role, Y)
        if role == "elbow" and lateral:   # an elbow about x bends sideways: outward < 0
            axis = -X if side == "l" else X
        hinge = tree.links[link].joint
        assert hinge is not None
        sign = 1 if float(pose.axis(link) @ axis) > 0 else -1
        out.append(JointRole(hinge.name, f"{side}_{role}", sign,
                             _wrap(pose.angles.get(hinge.name, 0.0)), link))
    return out


def _mirrored(a: Limb, b: Limb, scale: float) -> bool:
    pa, pb = np.asarray(a.end), np.asarray(b.end)
    d, s = pa - pb, pa + pb
    k = int(np.argmax(np.abs(d)))
    rest = np.delete(np.abs(d), k)
    return bool(rest.max() < 0.1 * scale and abs(s[k]) < 0.1 * scale)


def _pairs(tree: BodyTree, limbs: list[Limb], lo: int, hi: int) -> list[tuple[Limb, Limb]]:
    """Mirrored limb pairs with lo..hi hinges, as (right, left)."""
    out = []
    for i, a in enumerate(limbs):
        for b in limbs[i + 1:]:
            n = len(a.hinges)
            if n != len(b.hinges) or not lo <= n <= hi:
                continue
            scale = float(np.linalg.norm(a.end))
            if not _mirrored(a, b, scale):
                continue
            sa, sb = side_of(tree, a), side_of(tree, b)
            if {sa, sb} != {"l", "r"}:
                raise ConfigError(f"{tree.source}: limbs {tree.links[a.hinges[0]].name!r} and "
                                  f"{tree.links[b.hinges[0]].name!r} are a pair but their names do "
                                  "not say which is left (l_/left_...); name the joints with --map")
            out.append((a, b) if sa == "r" else (b, a))
    return out


def find_roles(tree: BodyTree) -> Roles:
    """Every hinge of ``tree`` given its role, sign and offset (see the module docstring)."""
    limbs = find_limbs(tree)
    legs = _pairs(tree, limbs, 5, 6)
    if len(legs) != 1:
        raise ConfigError(f"{tree.source}: found {len(legs)} pairs of mirrored limbs with 5 or 6 "
                          "joints where two legs were expected; name the joints with --map")
    leg_pair = legs[0]
    axes = robot_axes(tree, leg_pair)
    pose = Pose(tree, axes)
    joints: list[JointRole] = []
    order = "yaw_roll"
    for limb, side in zip(leg_pair, "rl", strict=True):
        feet = [i for i in range(len(tree.links)) if limb.last in tree.chain(i)]
        found, order = _leg_roles(pose, limb, side, feet)
        joints += found
    hips_z = min(pose.anchor(leg.hinges[0])[2] for leg in leg_pair)
    arm_pairs = [p for p in _pairs(tree, [m for m in limbs if m not in leg_pair], 3, 3)
                 if pose.anchor(p[0].hinges[0])[2] > hips_z]
    arms = arm_pairs[0] if len(arm_pairs) == 1 else None
    if arms is not None:
        for limb, side in zip(arms, "rl", strict=True):
            joints += _arm_roles(pose, limb, side)
    done = {j.link for j in joints}
    taken = {j.name for j in joints}
    for i, link in enumerate(tree.links):
        if link.joint is None or i in done:
            continue
        name = extra_name(link.joint.name)
        while name in taken:
            name = f"{name}_2"[:32]
        taken.add(name)
        joints.append(JointRole(link.joint.name, name, 1, 0.0, i))
    return Roles(axes, tuple(joints), leg_pair, arms, order)
