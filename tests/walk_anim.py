"""A walking character for the root-travel tests, written with bvhio from hand-chosen foot
placements, independently of robot/previs and of the gait: the character stands, walks
``steps`` steps at a chosen root speed (and turn rate), its feet planted in turn, then
stands again; its arms swing the whole time.

The legs are solved here by their own two-link geometry (hip roll then pitch, knee pitch,
the ankle keeping the sole level), in the Blender-style Z-up axes of tests/anim_files.py.
Lengths are the character's own [m]: legs of 0.45 + 0.45 m and a 0.14 m foot, so its leg
(root above the soles at rest) is 1.04 m; the robot walks it at 0.255 / 1.04 of the size.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from anim_files import BLENDER, in_axes
from bvhio import BvhContainer, BvhJoint, writeBvh
from pyglm import glm
from SpatialTransform import Pose

THIGH, SHIN, FOOT, HALF_HIPS = 0.45, 0.45, 0.14, 0.18
#: The character's leg: the root's height above its soles at rest [m].
RIG_LEG = THIGH + SHIN + FOOT
#: Standing hip height above the floor [m] (the knees bent about 1 rad).
STAND = 0.88 * (THIGH + SHIN) + FOOT
LIFT = 0.08                 # [m] swing foot height
FPS = 30.0


@dataclass(frozen=True)
class WalkShape:
    """stand_s [s] still, then ``steps`` steps of ``step_s`` [s] (the foot swings for
    ``swing`` of it) with the root at ``speed`` [m/s] turning at ``turn`` [rad/s], then
    ``after_s`` [s] still (the last step closes the feet in the first of it)."""

    speed: float = 0.33
    turn: float = 0.0
    steps: int = 12
    step_s: float = 0.5
    swing: float = 0.7
    stand_s: float = 2.0
    after_s: float = 2.5

    @property
    def walk_s(self) -> float:
        return self.steps * self.step_s

    @property
    def seconds(self) -> float:
        return self.stand_s + self.walk_s + self.after_s


def _root(shape: WalkShape, t: float) -> tuple[np.ndarray, float]:
    """The root's floor position (x, y) and heading at ``t`` [s]."""
    s = min(max(t - shape.stand_s, 0.0), shape.walk_s)
    if shape.turn == 0.0:
        return np.array([shape.speed * s, 0.0]), 0.0
    r = shape.speed / shape.turn
    psi = shape.turn * s
    return np.array([r * math.sin(psi), r * (1 - math.cos(psi))]), psi


def root_end(shape: WalkShape) -> tuple[np.ndarray, float]:
    """Where the root ends its walk: floor position (x forward, y left) [m, the
    character's] and heading [rad] from where it started."""
    return _root(shape, shape.seconds)


def _side(psi: float, foot: int) -> np.ndarray:
    sign = -1.0 if foot == 0 else 1.0
    return sign * HALF_HIPS * np.array([-math.sin(psi), math.cos(psi)])


def _foot(shape: WalkShape, t: float, foot: int) -> np.ndarray:
    """Sole point (x, y, z) of ``foot`` (0 right, 1 left) at ``t`` [s]: step k (right
    first) lifts at stand_s + k step_s and lands where the root will be one step on; a
    last step closes the feet."""
    moves = [k for k in range(shape.steps + 1) if k % 2 == foot]
    where = np.append(_root(shape, 0.0)[0] + _side(0.0, foot), 0.0)
    for k in moves:
        lift = shape.stand_s + k * shape.step_s
        land_t = min(lift + shape.step_s, shape.stand_s + shape.walk_s)
        p, psi = _root(shape, land_t)
        target = np.append(p + _side(psi, foot), 0.0)
        u = (t - lift) / (shape.swing * shape.step_s)
        if u <= 0:
            break
        if u < 1:
            e = (1 - math.cos(math.pi * u)) / 2
            where = where + e * (target - where)
            where[2] = LIFT * math.sin(math.pi * u)
            break
        where = target
    return where


def _leg(d: np.ndarray) -> tuple[float, float, float]:
    """Hip roll, hip pitch, knee [rad] putting the ankle at ``d`` from the hip (robot axes
    of the pelvis: x forward, y left, z up)."""
    reach = float(np.linalg.norm(d))
    knee = math.acos(max(-1.0, min(1.0, (reach ** 2 - THIGH ** 2 - SHIN ** 2)
                                   / (2 * THIGH * SHIN))))
    roll = math.atan2(d[1], -d[2])
    h = math.hypot(d[1], d[2])
    v = np.array([-SHIN * math.sin(knee), -THIGH - SHIN * math.cos(knee)])  # (x, z), thigh frame
    pitch = math.atan2(v[0], -v[1]) - math.atan2(d[0], h)
    return roll, pitch, knee


def angles(shape: WalkShape, t: float) -> dict[str, float]:
    """Every animated joint's angle [rad] at ``t`` [s] (robot names and axes)."""
    p, psi = _root(shape, t)
    out = {"r_shoulder_pitch": 0.3 * math.sin(2.0 * t), "l_shoulder_pitch": -0.3 * math.sin(2.0 * t),
           "r_elbow": -0.4, "l_elbow": -0.4}
    c, s = math.cos(psi), math.sin(psi)
    for foot, side in ((0, "r"), (1, "l")):
        hip = np.append(p + _side(psi, foot), STAND)
        ankle = _foot(shape, t, foot) + np.array([0.0, 0.0, FOOT])
        w = ankle - hip
        d = np.array([c * w[0] + s * w[1], -s * w[0] + c * w[1], w[2]])
        roll, pitch, knee = _leg(d)
        out |= {f"{side}_hip_roll": roll, f"{side}_hip_pitch": pitch, f"{side}_knee": knee,
                f"{side}_ankle_pitch": -(pitch + knee), f"{side}_ankle_roll": -roll}
    return out


#: bone → (parent, offset in robot axes [m], its joints with their robot axes in order).
BONES: dict[str, tuple[str | None, tuple[float, float, float], tuple[tuple[str, str], ...]]] = {
    "pelvis": (None, (0.0, 0.0, 0.0), ()),
    "r_hip": ("pelvis", (0.0, -HALF_HIPS, 0.0), (("x", "r_hip_roll"), ("y", "r_hip_pitch"))),
    "r_knee": ("r_hip", (0.0, 0.0, -THIGH), (("y", "r_knee"),)),
    "r_ankle": ("r_knee", (0.0, 0.0, -SHIN), (("y", "r_ankle_pitch"), ("x", "r_ankle_roll"))),
    "l_hip": ("pelvis", (0.0, HALF_HIPS, 0.0), (("x", "l_hip_roll"), ("y", "l_hip_pitch"))),
    "l_knee": ("l_hip", (0.0, 0.0, -THIGH), (("y", "l_knee"),)),
    "l_ankle": ("l_knee", (0.0, 0.0, -SHIN), (("y", "l_ankle_pitch"), ("x", "l_ankle_roll"))),
    "chest": ("pelvis", (0.0, 0.0, 0.5), ()),
    "r_shoulder": ("chest", (0.0, -0.2, 0.0), (("y", "r_shoulder_pitch"),)),
    "r_elbow": ("r_shoulder", (0.0, 0.0, -0.3), (("y", "r_elbow"),)),
    "l_shoulder": ("chest", (0.0, 0.2, 0.0), (("y", "l_shoulder_pitch"),)),
    "l_elbow": ("l_shoulder", (0.0, 0.0, -0.3), (("y", "l_elbow"),)),
}
ENDS = {"r_ankle": (0.0, 0.0, -FOOT), "l_ankle": (0.0, 0.0, -FOOT), "chest": (0.0, 0.0, 0.3),
        "r_elbow": (0.0, 0.0, -0.25), "l_elbow": (0.0, 0.0, -0.25)}


def write_walk_bvh(path: str, shape: WalkShape) -> None:
    """The walking character as a Blender-style BVH (Z up, six channels everywhere)."""
    joints: dict[str, BvhJoint] = {}
    for name, (parent, off, _) in BONES.items():
        j = BvhJoint(name, glm.vec3(*in_axes(off, BLENDER)))
        j.Channels = ["Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation",
                      "Yrotation"]
        if name in ENDS:
            j.EndSite = glm.vec3(*in_axes(ENDS[name], BLENDER))
        joints[name] = j
        if parent is not None:
            joints[parent].Children.append(j)
    frames = int(round(shape.seconds * FPS)) + 1
    for k in range(frames):
        t = k / FPS
        a = angles(shape, t)
        p, psi = _root(shape, t)
        for name, j in joints.items():
            q = glm.quat(1.0, 0.0, 0.0, 0.0)
            if name == "pelvis":
                q = glm.angleAxis(psi, glm.vec3(*BLENDER["z"]))
            for axis, joint in BONES[name][2]:
                q = q * glm.angleAxis(a[joint], glm.vec3(*BLENDER[axis]))
            pos = j.Offset
            if name == "pelvis":
                pos = glm.vec3(*in_axes((p[0], p[1], STAND), BLENDER))
            j.Keyframes.append(Pose(pos, q))
    writeBvh(path, BvhContainer(joints["pelvis"], frames, 1.0 / FPS), percision=9)
