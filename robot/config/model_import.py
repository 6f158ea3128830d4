"""``biped robots import``: a URDF or MJCF model → a robot file of numbers (the joints as
every robot file has them, plus the model's body as ``[model]``), and a summary.

What each joint gets (robot/body/roles.py finds the roles, signs and offsets):
- ``model_joint``, ``model_sign``, ``model_offset``: the model's own name and convention;
- ``servo_id``: from ``--map``, else numbered in the project's order (right leg hip to
  ankle, left leg, right arm, left arm, extra joints in the model's order) from 1;
- ``sign``, ``zero_ticks``: the servo's positive direction taken as the model joint's, its
  centre tick at the model's zero;
- limits: the model's range (in the project's convention); where the model has none, the
  map's, else the servo's whole range (a warning names each such joint);
- ``max_speed_rad_s``: the model's velocity limit, else the servo's no-load speed, at most
  the map's.

Which way the knees bend (robot.body.legs.LegChain.knee_back): the map's ``knee``
("forward" or "back"), else backward only where the limits let the rest crouch (``REST``)
bend the knee backward but not forward (the summary says so), else forward.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robot.body.limbs import torso_links
from robot.body.measure import Measured, measure
from robot.body.model import BodyModel
from robot.body.roles import Roles, find_roles
from robot.body.tree import BodyTree, Frame, Link, matrix_to_quat
from robot.config.joint_names import ARM_NAMES, LEG_NAMES
from robot.config.model_recipe import KNEES
from robot.errors import ConfigError
from robot.servo.models import MODELS, ServoModel

#: A frame on the torso whose name says it is the IMU's (onshape-to-robot's "imu" frame).
IMU_FRAME = re.compile(r"imu|bno0?55", re.IGNORECASE)
#: The rest pose of a straight-legged robot [rad]: knees bent as the bundled robots rest
#: (a knee that bends backward: each angle negated).
REST = {"hip_pitch": -0.55, "knee": 1.1, "ankle_pitch": -0.55}
@dataclass(frozen=True)
class JointEntry:
    """One ``[joints.NAME]`` table (project convention) and where its limits came from."""

    name: str
    model_joint: str
    model_sign: int
    model_offset: float
    servo_id: int
    sign: int
    zero_ticks: int
    min_rad: float
    max_rad: float
    max_speed_rad_s: float
    limits_source: str
    fixed_rad: float | None = None
    gains: Mapping[str, int] = field(default_factory=dict)   # the map's gain registers


@dataclass
class Imported:
    """What an import found: the body, the joints, the measured lengths, the warnings."""

    model: BodyModel
    joints: list[JointEntry]
    measured: Measured
    roles: Roles
    warnings: list[str] = field(default_factory=list)
    knees: str = "knees bend forward"   # which way the knees bend, and why

    @property
    def rest(self) -> dict[str, float]:
        out = {}
        names = {j.name: j for j in self.joints}
        for side, leg in zip("rl", self.model.legs, strict=True):
            for part, q in REST.items():
                j = names.get(f"{side}_{part}")
                if j is not None:
                    q = -q if leg.knee_back else q
                    out[j.name] = min(max(q, j.min_rad), j.max_rad)
        return out


def _fits(joints: list[JointEntry], sign: float) -> bool:
    """Whether every leg joint of ``REST`` (times ``sign``) is inside its limits."""
    names = {j.name: j for j in joints}
    return all(j.min_rad <= sign * q <= j.max_rad for side in "rl" for part, q in REST.items()
               if (j := names.get(f"{side}_{part}")) is not None)


def knee_back(joints: list[JointEntry], knee: str | None) -> tuple[bool, str]:
    """Whether the knees bend backward, and why (the module docstring): ``knee`` the map's
    ("forward", "back" or None)."""
    if knee is not None:
        if knee not in KNEES:
            raise ConfigError(f"--map: knee: {knee!r}; valid: {', '.join(KNEES)}")
        return KNEES[knee], f"knees bend {'backward' if KNEES[knee] else 'forward'} (--map)"
    if not _fits(joints, 1.0) and _fits(joints, -1.0):
        return True, ("knees bend backward: the leg limits let the rest crouch bend them "
                      "backward only (--map knee = \"forward\" to override)")
    return False, "knees bend forward"


def _sole_frames(tree: BodyTree, roles: Roles, m: Measured) -> BodyTree:
    """The tree with a ``r_sole`` / ``l_sole`` frame on each foot (the sole point) and an
    ``imu`` frame on the root, in the robot's axes: where a torso frame named for an IMU
    is (IMU_FRAME), else at the torso's centre of mass."""
    by = roles.by_name()
    pose_angles = {j.model_joint: j.offset for j in roles.joints}
    pos, rot = tree.poses(pose_angles)
    axes = roles.axes
    links = list(tree.links)
    for side, leg in zip("rl", m.legs, strict=True):
        foot = roles.legs[0 if side == "r" else 1].last
        sole_robot = np.asarray(leg.zero_sole()) + m.origin
        local = rot[foot].T @ (axes.T @ sole_robot - pos[foot])
        quat = matrix_to_quat(rot[foot].T @ axes.T)
        link = links[foot]
        links[foot] = Link(link.name, link.parent, link.pos, link.quat, link.inertial, link.joint,
                           link.shapes, (*link.frames, Frame(f"{side}_sole", tuple(map(float, local)),  # type: ignore[arg-type]
                                                               quat)))
    torso = sorted(torso_links(tree))
    weighed = [(link.inertial.mass, pos[i] + rot[i] @ np.asarray(link.inertial.com))
               for i in torso if (link := tree.links[i]).inertial is not None]
    mass = sum(w for w, _ in weighed)
    mount = sum((w * c for w, c in weighed), np.zeros(3)) / max(mass, 1e-12)
    marked = [pos[i] + rot[i] @ np.asarray(f.pos) for i in torso for f in links[i].frames
              if IMU_FRAME.search(f.name)]
    if marked:      # the model's own IMU frame: the sensor sits there
        mount = marked[0]
    links = [dataclasses.replace(link, frames=tuple(f for f in link.frames if f.name != "imu"))
             for link in links]
    root = links[0]
    links[0] = Link(root.name, -1, root.pos, root.quat, root.inertial, None, root.shapes,
                    (*root.frames, Frame("imu", (float(mount[0]), float(mount[1]), float(mount[2])),
                                         matrix_to_quat(axes.T))))
    del by
    return BodyTree(tuple(links), source=tree.source, excludes=tree.excludes)


def _order(name: str) -> tuple[int, int]:
    order = [*LEG_NAMES, *ARM_NAMES]
    return (order.index(name), 0) if name in order else (len(order), 0)


def build(tree: BodyTree, *, servo: ServoModel, joint_map: dict[str, dict[str, object]],
          file: str, source: str = "", licence: str = "", knee: str | None = None) -> Imported:
    """Roles, measurements and joint tables of ``tree`` (see the module docstring). A
    model joint the map marks ``weld = true`` (one no servo drives: a PWM servo off the
    bus, a passive part) is welded at the model's zero; ``knee``: the map's (``KNEES``)."""
    welded = [n for n, e in joint_map.items() if e.get("weld") is True]
    missing = [n for n in welded if n not in tree.joint_link]
    if missing:
        raise ConfigError(f"--map: joints.{missing[0]}: the model has no joint of that name; "
                          f"valid: {', '.join(tree.joint_link)}")
    if welded:
        tree = dataclasses.replace(tree, links=tuple(
            dataclasses.replace(link, joint=None) if link.joint and link.joint.name in welded
            else link for link in tree.links))
        joint_map = {n: e for n, e in joint_map.items() if n not in welded}
    roles = find_roles(tree)
    m = measure(tree, roles)
    warnings: list[str] = []
    unknown = sorted(set(joint_map) - {j.model_joint for j in roles.joints})
    if unknown:
        raise ConfigError(f"--map: joints.{unknown[0]}: the model has no joint of that name; "
                          f"valid: {', '.join(j.model_joint for j in roles.joints)}")
    tree2 = _sole_frames(tree, roles, m)
    model = BodyModel(tree2, tuple(tuple(map(float, r)) for r in roles.axes),  # type: ignore[arg-type]
                      tuple(map(float, m.origin @ roles.axes)), m.legs, file, source, licence)  # type: ignore[arg-type]
    ordered = sorted(roles.joints, key=lambda j: _order(j.name))
    ids_used: set[int] = set()
    unlimited: list[str] = []
    joints = []
    for k, role in enumerate(ordered):
        entry = joint_map.get(role.model_joint, {})
        name = str(entry.get("name", role.name))
        if "name" in entry and (role.name in LEG_NAMES or role.name in ARM_NAMES) and name != role.name:
            raise ConfigError(f"--map: joints.{role.model_joint}.name: {name!r}, but the importer "
                              f"found it is {role.name} from its axis and place in the leg or arm")
        servo_id = int(entry.get("servo_id", k + 1))  # type: ignore[call-overload]
        if servo_id in ids_used:
            raise ConfigError(f"--map: joints.{role.model_joint}.servo_id: {servo_id} is taken twice")
        ids_used.add(servo_id)
        hinge = tree.links[role.link].joint
        assert hinge is not None
        per_rad = servo.ticks_per_rad
        centre = servo.resolution // 2
        model_range = hinge.range
        src = "the model's range"
        if model_range is None and "model_range" in entry:
            raw = entry["model_range"]
            if not (isinstance(raw, list) and len(raw) == 2 and all(
                    isinstance(v, int | float) and math.isfinite(v) for v in raw) and raw[0] < raw[1]):
                raise ConfigError(f"--map: joints.{role.model_joint}.model_range: expected [lo, hi] "
                                  f"[rad] with lo < hi, got {raw!r}")
            model_range = (float(raw[0]), float(raw[1]))
            src = str(entry.get("limits_source", "--map"))
        if model_range is not None:
            ends = sorted(((model_range[0] - role.offset) * role.sign,
                           (model_range[1] - role.offset) * role.sign))
            lo, hi = ends[0], ends[1]
        elif "min_rad" in entry and "max_rad" in entry:
            lo, hi = float(entry["min_rad"]), float(entry["max_rad"])  # type: ignore[arg-type]
            src = str(entry.get("limits_source", "--map"))
        else:
            half = 0.5 * (servo.resolution - 1) / per_rad
            lo, hi = -half - role.offset * role.sign, half - role.offset * role.sign
            lo, hi = sorted((lo, hi))
            src = f"the {servo.name}'s whole range (the model gives none)"
            unlimited.append(role.model_joint)
        lo, hi = max(lo, -math.pi), min(hi, math.pi)
        speed = servo.no_load_speed if hinge.velocity is None else min(hinge.velocity, servo.no_load_speed)
        speed = min(speed, float(entry.get("max_speed_rad_s", speed)))  # type: ignore[arg-type]
        zero = int(round(centre + role.offset * per_rad))
        fixed = None
        if name not in LEG_NAMES and name not in ARM_NAMES:
            fixed = min(max(float(entry.get("fixed_rad", 0.0)), lo), hi)  # type: ignore[arg-type]
        joints.append(JointEntry(name, role.model_joint, role.sign, role.offset, servo_id,
                                 role.sign, zero, lo, hi, round(min(speed, 20.0), 3), src, fixed,
                                 dict(entry.get("gains", {}))))  # type: ignore[call-overload]
    if unlimited:
        warnings.append(f"no joint limits in the model for {', '.join(unlimited)}: each gets "
                        f"the {servo.name}'s whole range; give real limits with --map "
                        "(min_rad, max_rad, limits_source)")
    back, why = knee_back(joints, knee)
    if back:
        model = dataclasses.replace(model, legs=tuple(  # type: ignore[arg-type]
            dataclasses.replace(leg, knee_back=True) for leg in model.legs))
    return Imported(model, joints, m, roles, warnings, why)


def check_servo(kind: str, model: str) -> ServoModel:
    if model not in MODELS:
        raise ConfigError(f"--model: unknown servo model {model!r}; valid: {', '.join(MODELS)}")
    return MODELS[model]


def summary(imp: Imported, *, path: Path) -> list[str]:
    """What the import found, a line each."""
    legs = imp.measured.legs
    layout = ("6-DoF" if legs[0].has_yaw and legs[0].has_ankle_roll else "5-DoF") + " legs: " + \
        "-".join(j.name[2:] for j in imp.joints if j.name.startswith("r_") and j.name in LEG_NAMES)
    g = imp.measured.lengths
    arms = "arms 2 x 3" if imp.roles.arms is not None else "no arms"
    extras = [j.name for j in imp.joints if j.fixed_rad is not None]
    out = [f"{path}: {len(imp.joints)} joints: {layout}; {arms}; "
           f"extra: {', '.join(extras) or 'none'}",
           f"  mass {imp.model.tree.mass:.3f} kg; legs: thigh {1000 * g['thigh']:.1f} mm, shin "
           f"{1000 * g['shin']:.1f} mm, ankle to sole {1000 * g['ankle_height']:.1f} mm, hips "
           f"{1000 * g['hip_width']:.1f} mm apart at the soles",
           f"  sole {1000 * g['foot_length']:.1f} x {1000 * g['foot_width']:.1f} mm, centre "
           f"{1000 * g['foot_forward']:+.1f} mm ahead of the ankle",
           f"  offsets: yaw axis {1000 * _yaw_off(legs[0]):.1f} mm off the hip, roll-pitch "
           f"{1000 * legs[0].roll_drop:.1f} mm, sideways {1000 * abs(legs[0].lateral):.1f} mm, ankle "
           f"{1000 * legs[0].ankle_drop:.1f} mm; hip order {legs[0].order}; {imp.knees}"]
    ids = ", ".join(f"{j.name} {j.servo_id}" for j in imp.joints)
    out.append(f"  servo ids: {ids}")
    out += [f"  warning: {w}" for w in imp.warnings]
    return out


def _yaw_off(leg: object) -> float:
    from robot.body.legs import LegChain

    assert isinstance(leg, LegChain)
    if leg.yaw_axis is None:
        return 0.0
    return math.hypot(leg.yaw_axis[0] - leg.hip[0], leg.yaw_axis[1] - leg.hip[1])
