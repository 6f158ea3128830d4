"""What the gait and the IK need, measured on a model at the project's zero pose (the
offsets robot/body/roles.py found): each leg's chain (robot/body/legs.py) and the dozen
lengths of ``Geometry`` the gait scales by.

The pelvis frame: the robot's axes (REP-103), its origin midway between the two hips'
pitch axes (each taken where the hip roll axis crosses the leg's sagittal plane). The sole
point of a leg is on the lowest face of its foot's shapes, straight below the ankle roll
axis (without ankle roll: below the ankle pitch axis, at the sole's middle sideways); the
sole's extent is the box around the foot's shape points on that face.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robot.body.legs import LegChain
from robot.body.pose import Pose
from robot.body.roles import SOLE_BAND, Roles
from robot.body.tree import Array, BodyTree
from robot.errors import ConfigError

#: Largest misplacement of a knee or ankle axis from straight below the hip at the zero
#: pose that is taken for a straight leg [m] (the offsets make it ~1e-15 m).
STRAIGHT_TOL = 1e-4


@dataclass(frozen=True)
class Sole:
    """A foot's sole at the zero pose in the pelvis frame [m]: height, and its extent."""

    z: float
    x_min: float
    x_max: float
    y_min: float
    y_max: float

    @property
    def centre(self) -> tuple[float, float]:
        return (0.5 * (self.x_min + self.x_max), 0.5 * (self.y_min + self.y_max))


@dataclass(frozen=True)
class Measured:
    """origin: the pelvis origin in the robot-axes root frame [m]; legs: (right, left);
    soles: (right, left); lengths: Geometry's fields [m]."""

    origin: Array
    legs: tuple[LegChain, LegChain]
    soles: tuple[Sole, Sole]
    lengths: dict[str, float]


def _foot_links(tree: BodyTree, last: int) -> list[int]:
    return [i for i in range(len(tree.links)) if last in tree.chain(i)]


def _sole(pose: Pose, links: list[int]) -> Sole:
    pts = pose.points(links)
    low = pts[pts[:, 2] <= pts[:, 2].min() + SOLE_BAND]
    return Sole(float(pts[:, 2].min()), float(low[:, 0].min()), float(low[:, 0].max()),
                float(low[:, 1].min()), float(low[:, 1].max()))


def _leg(pose: Pose, roles: Roles, side: str, where: str) -> tuple[dict[str, Array], Sole]:
    """Per role, the axis anchor (robot frame, root origin); the sole."""
    by = roles.by_name()
    anchors = {r: pose.anchor(by[f"{side}_{r}"].link) for r in
               ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
               if f"{side}_{r}" in by}
    limb = roles.legs[0 if side == "r" else 1]
    sole = _sole(pose, _foot_links(pose.tree, limb.last))
    x_p = anchors["hip_pitch"][0]
    for part in ("knee", "ankle_pitch"):
        off = anchors[part][0] - x_p
        if abs(off) > STRAIGHT_TOL:
            raise ConfigError(f"{where}: {by[f'{side}_{part}'].model_joint}: {1000 * off:.2f} mm "
                              "ahead of the hip pitch axis with the leg straightened")
    return anchors, sole


def measure(tree: BodyTree, roles: Roles) -> Measured:
    """The legs' chains, the soles and Geometry's lengths (see the module docstring)."""
    pose = Pose(tree, roles.axes)
    pose.angles = {j.model_joint: j.offset for j in roles.joints}
    pose.update()
    where = tree.source
    found = [_leg(pose, roles, s, where) for s in "rl"]
    pitch_points = [np.array([a["hip_pitch"][0], a["hip_roll"][1], a["hip_pitch"][2]])
                    for a, _ in found]
    origin = 0.5 * (pitch_points[0] + pitch_points[1])
    legs, soles = [], []
    for side, (a, sole) in zip("rl", found, strict=True):
        x_p, z_p = a["hip_pitch"][0], a["hip_pitch"][2]
        y_r, z_r = a["hip_roll"][1], a["hip_roll"][2]
        z_k, z_a = a["knee"][2], a["ankle_pitch"][2]
        if "ankle_roll" in a:
            y_ar, z_ar = a["ankle_roll"][1], a["ankle_roll"][2]
        else:
            y_ar, z_ar = sole.centre[1], z_a
        yaw = a.get("hip_yaw")
        o = origin
        legs.append(LegChain(
            side, (float(x_p - o[0]), float(y_r - o[1]), float(z_r - o[2])),
            float(z_p - z_k), float(z_k - z_a), (0.0, 0.0, float(sole.z - z_ar)),
            yaw_axis=None if yaw is None else (float(yaw[0] - o[0]), float(yaw[1] - o[1])),
            roll_drop=float(z_r - z_p), lateral=float(y_ar - y_r), ankle_drop=float(z_a - z_ar),
            has_ankle_roll="ankle_roll" in a, order=roles.order))
        soles.append(Sole(float(sole.z - o[2]), float(sole.x_min - o[0]), float(sole.x_max - o[0]),
                          float(sole.y_min - o[1]), float(sole.y_max - o[1])))
    right, left = legs
    lengths = {
        "hip_width": left.zero_sole()[1] - right.zero_sole()[1],
        "thigh": 0.5 * (right.thigh + left.thigh), "shin": 0.5 * (right.shin + left.shin),
        "ankle_height": 0.5 * (right.ankle_height + left.ankle_height),
        "foot_length": 0.5 * sum(s.x_max - s.x_min for s in soles),
        "foot_width": 0.5 * sum(s.y_max - s.y_min for s in soles),
        "foot_forward": 0.5 * sum(s.centre[0] - leg.hip[0] for s, leg in zip(soles, legs, strict=True)),
    }
    lengths.update(_torso(pose, roles, origin))
    return Measured(origin, (right, left), (soles[0], soles[1]), lengths)


def _torso(pose: Pose, roles: Roles, origin: Array) -> dict[str, float]:
    """torso_height, torso_depth and (with arms) shoulder_width, upper_arm, forearm [m]."""
    from robot.body.limbs import torso_links

    tree = pose.tree
    body = pose.points(sorted(torso_links(tree)))
    out = {"torso_depth": float(body[:, 0].max() - body[:, 0].min())}
    if roles.arms is None:
        out["torso_height"] = float(body[:, 2].max() - origin[2])
        return out
    by = roles.by_name()
    sides = []
    for side in "rl":
        roll = pose.anchor(by[f"{side}_shoulder_roll"].link)
        elbow = pose.anchor(by[f"{side}_elbow"].link)
        hand = pose.points(_foot_links(tree, by[f"{side}_elbow"].link))
        reach = float(np.max(np.linalg.norm(hand - elbow, axis=1)))
        sides.append((roll, float(np.linalg.norm(elbow - roll)), reach))
    out["torso_height"] = float(0.5 * (sides[0][0][2] + sides[1][0][2]) - origin[2])
    out["shoulder_width"] = float(sides[1][0][1] - sides[0][0][1])
    out["upper_arm"] = 0.5 * (sides[0][1] + sides[1][1])
    out["forearm"] = 0.5 * (sides[0][2] + sides[1][2])
    return out
