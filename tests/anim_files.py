"""Animation files for the import tests, written with bvhio and pygltflib from hand-chosen
joint angles, independently of `biped export` and of robot/previs: their own axes (Blender's
Z-up, glTF's Y-up), their own bone names and rest rotations, their own quaternion
arithmetic (glm in bvhio; numpy here)."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

import numpy as np
import pygltflib as gl
from bvhio import BvhContainer, BvhJoint, writeBvh
from pyglm import glm
from SpatialTransform import Pose

#: A four-joint hierarchy in our skeleton's names, the right knee's Xrotation its pitch (15
#: channels a frame: the root's 6, then 3 each), up to its MOTION line.
KNEE_HIERARCHY = [
    "HIERARCHY", "ROOT pelvis", "{", "OFFSET 0 0 0",
    "CHANNELS 6 Xposition Yposition Zposition Yrotation Zrotation Xrotation",
    "JOINT r_hip", "{", "OFFSET -5 0 0", "CHANNELS 3 Yrotation Zrotation Xrotation",
    "JOINT r_knee", "{", "OFFSET 0 -10 0", "CHANNELS 3 Zrotation Yrotation Xrotation",
    "End Site", "{", "OFFSET 0 -10 0", "}", "}", "}",
    "JOINT l_hip", "{", "OFFSET 5 0 0", "CHANNELS 3 Yrotation Zrotation Xrotation",
    "End Site", "{", "OFFSET 0 -20 0", "}", "}", "}", "MOTION"]

#: The chosen motion: joint → angle [rad] at time t [s]; each inside the default robot's
#: limits and speeds.
ANGLES: dict[str, Callable[[float], float]] = {
    "r_hip_yaw": lambda t: 0.15 * math.sin(2.0 * t),
    "r_hip_roll": lambda t: 0.1 * math.sin(3.0 * t + 0.3),
    "r_hip_pitch": lambda t: -0.4 * math.sin(2.5 * t),
    "r_knee": lambda t: 0.5 + 0.4 * math.sin(2.5 * t),
    "r_ankle_pitch": lambda t: -0.2 * math.sin(2.5 * t + 1.0),
    "r_ankle_roll": lambda t: 0.08 * math.cos(3.0 * t),
    "l_hip_yaw": lambda t: -0.1 * math.sin(1.5 * t),
    "l_hip_roll": lambda t: 0.12 * math.sin(2.0 * t),
    "l_hip_pitch": lambda t: 0.3 * math.sin(2.0 * t + 0.5),
    "l_knee": lambda t: 0.6 + 0.3 * math.sin(2.0 * t),
    "l_ankle_pitch": lambda t: 0.1 * math.sin(2.0 * t),
    "l_ankle_roll": lambda t: -0.05 * math.sin(3.0 * t),
    "r_shoulder_pitch": lambda t: -0.8 * math.sin(1.5 * t),
    "r_shoulder_roll": lambda t: -0.3 - 0.2 * math.sin(2.0 * t),
    "r_elbow": lambda t: -0.6 - 0.3 * math.sin(2.0 * t),
    "l_shoulder_pitch": lambda t: 0.5 * math.sin(1.2 * t),
    "l_shoulder_roll": lambda t: 0.3 + 0.2 * math.sin(2.0 * t),
    "l_elbow": lambda t: -0.5 - 0.2 * math.cos(2.0 * t),
}
#: bone → its joints with their robot axes, in the order the robot composes them.
BONES: dict[str, tuple[tuple[str, str], ...]] = {
    "r_hip": (("z", "r_hip_yaw"), ("x", "r_hip_roll"), ("y", "r_hip_pitch")),
    "r_knee": (("y", "r_knee"),),
    "r_ankle": (("y", "r_ankle_pitch"), ("x", "r_ankle_roll")),
    "l_hip": (("z", "l_hip_yaw"), ("x", "l_hip_roll"), ("y", "l_hip_pitch")),
    "l_knee": (("y", "l_knee"),),
    "l_ankle": (("y", "l_ankle_pitch"), ("x", "l_ankle_roll")),
    "r_shoulder": (("y", "r_shoulder_pitch"), ("x", "r_shoulder_roll")),
    "r_elbow": (("y", "r_elbow"),),
    "l_shoulder": (("y", "l_shoulder_pitch"), ("x", "l_shoulder_roll")),
    "l_elbow": (("y", "l_elbow"),),
}
#: A human-ish rig in robot axes (x forward, y left, z up) [m]: parent, offset, end site.
RIG: dict[str, tuple[str | None, tuple[float, float, float]]] = {
    "pelvis": (None, (0.0, 0.0, 0.0)),
    "r_hip": ("pelvis", (0.0, -0.09, -0.05)), "r_knee": ("r_hip", (0.0, 0.0, -0.42)),
    "r_ankle": ("r_knee", (0.0, 0.0, -0.40)),
    "l_hip": ("pelvis", (0.0, 0.09, -0.05)), "l_knee": ("l_hip", (0.0, 0.0, -0.42)),
    "l_ankle": ("l_knee", (0.0, 0.0, -0.40)),
    "chest": ("pelvis", (0.0, 0.0, 0.45)),
    "r_shoulder": ("chest", (0.0, -0.18, 0.0)), "r_elbow": ("r_shoulder", (0.0, 0.0, -0.28)),
    "l_shoulder": ("chest", (0.0, 0.18, 0.0)), "l_elbow": ("l_shoulder", (0.0, 0.0, -0.28)),
}
ENDS = {"r_ankle": (0.05, 0.0, -0.08), "l_ankle": (0.05, 0.0, -0.08),
        "r_elbow": (0.0, 0.0, -0.25), "l_elbow": (0.0, 0.0, -0.25)}
#: Robot axes in Blender's (Z up, the character facing -Y, its left +X) and glTF's (Y up,
#: facing +Z, left +X).
BLENDER = {"x": (0.0, -1.0, 0.0), "y": (1.0, 0.0, 0.0), "z": (0.0, 0.0, 1.0)}
GLTF = {"x": (0.0, 0.0, 1.0), "y": (1.0, 0.0, 0.0), "z": (0.0, 1.0, 0.0)}
#: Blender writes every joint with its own Euler order; a mix of them.
ORDERS = ("Zrotation Xrotation Yrotation", "Xrotation Yrotation Zrotation",
          "Yrotation Zrotation Xrotation", "Zrotation Yrotation Xrotation")


def in_axes(v: tuple[float, float, float], axes: Mapping[str, tuple[float, float, float]]
            ) -> np.ndarray:
    return sum(c * np.array(axes[a]) for c, a in zip(v, "xyz", strict=True))  # type: ignore[return-value]


def write_blender_bvh(path: str, fps: float, frames: int, *, travel_m_s: float = 0.3) -> None:
    """A Blender-style BVH: Z up, six channels on every joint, mixed rotation orders."""
    joints: dict[str, BvhJoint] = {}
    for i, (name, (parent, off)) in enumerate(RIG.items()):
        j = BvhJoint(name, glm.vec3(*in_axes(off, BLENDER)))
        j.Channels = ["Xposition", "Yposition", "Zposition", *ORDERS[i % len(ORDERS)].split()]
        if name in ENDS:
            j.EndSite = glm.vec3(*in_axes(ENDS[name], BLENDER))
        elif name == "chest":
            j.EndSite = glm.vec3(0.0, 0.0, 0.2)
        joints[name] = j
        if parent is not None:
            joints[parent].Children.append(j)
    for k in range(frames):
        t = k / fps
        for name, j in joints.items():
            q = glm.quat(1.0, 0.0, 0.0, 0.0)
            for axis, joint in BONES.get(name, ()):
                q = q * glm.angleAxis(ANGLES[joint](t), glm.vec3(*BLENDER[axis]))
            pos = j.Offset
            if name == "pelvis":
                pos = glm.vec3(*in_axes((travel_m_s * t, 0.0, 0.9), BLENDER))
            j.Keyframes.append(Pose(pos, q))
    writeBvh(path, BvhContainer(joints["pelvis"], frames, 1.0 / fps), percision=9)


# ------------------------------------------------------------------------------ glTF
def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of (x, y, z, w) quaternions."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array([aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz])


def qinv(q: np.ndarray) -> np.ndarray:
    return np.array([-q[0], -q[1], -q[2], q[3]])


def qaxis(axis: np.ndarray, angle: float) -> np.ndarray:
    return np.array([*(np.asarray(axis) * math.sin(angle / 2)), math.cos(angle / 2)])


def qrot(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    return qmul(qmul(q, np.array([*v, 0.0])), qinv(q))[:3]


#: Blender-like names for the glTF rig, and the map a designer would write for it: the
#: rig's knees turn the other way (sign -1) and its left elbow's rest is bent 0.2 rad.
GLTF_NAMES = {"pelvis": "hips", "r_hip": "thigh.R", "r_knee": "shin.R", "r_ankle": "foot.R",
              "l_hip": "thigh.L", "l_knee": "shin.L", "l_ankle": "foot.L", "chest": "chest",
              "r_shoulder": "upper_arm.R", "r_elbow": "forearm.R",
              "l_shoulder": "upper_arm.L", "l_elbow": "forearm.L"}
SIGN = {"r_knee": -1.0, "l_knee": -1.0}
OFFSET = {"l_elbow": 0.2}


def map_toml() -> str:
    lines = ["# the glTF test rig (tests/anim_files.py) → the default robot"]
    for bone, joints in BONES.items():
        for axis, joint in joints:
            lines += [f"[joints.{joint}]", f'bone = "{GLTF_NAMES[bone]}"', f'axis = "{axis}"',
                      f"sign = {int(SIGN.get(joint, 1.0))}",
                      f"offset = {OFFSET.get(joint, 0.0)}", ""]
    return "\n".join(lines)


def write_blender_gltf(path: str, fps: float, frames: int) -> None:
    """A Blender-style glTF: Y up, bones with rest rotations under an armature node, a key
    on every frame; each bone's animated local rotation from its chosen world delta."""
    rng = np.random.default_rng(7)
    names = list(RIG)
    pos: dict[str, np.ndarray] = {}
    rest_world: dict[str, np.ndarray] = {}
    for name, (parent, off) in RIG.items():
        pos[name] = (pos[parent] if parent else np.zeros(3)) + in_axes(off, GLTF)
        q = rng.normal(size=4)
        rest_world[name] = q / np.linalg.norm(q)
    nodes = [gl.Node(name="Armature", children=[1])]
    local_rest: dict[str, np.ndarray] = {}
    for name in names:
        parent = RIG[name][0]
        wp = rest_world[parent] if parent else np.array([0.0, 0.0, 0.0, 1.0])
        local_rest[name] = qmul(qinv(wp), rest_world[name])
        t = qrot(qinv(wp), pos[name] - (pos[parent] if parent else np.zeros(3)))
        if parent is None:
            t = pos[name] + np.array([0.0, 0.9, 0.0])
        nodes.append(gl.Node(name=GLTF_NAMES[name], rotation=local_rest[name].tolist(),
                             translation=t.tolist()))
    for name in names:
        parent = RIG[name][0]
        if parent:
            nodes[1 + names.index(parent)].children.append(1 + names.index(name))
    for name, end in ENDS.items():      # end sites: leaf nodes that are no joints
        nodes[1 + names.index(name)].children.append(len(nodes))
        nodes.append(gl.Node(name=f"{GLTF_NAMES[name]}_end",
                             translation=qrot(qinv(rest_world[name]), in_axes(end, GLTF)).tolist()))
    out = np.zeros((frames, len(names), 4))
    for k in range(frames):
        t = k / fps
        delta: dict[str, np.ndarray] = {}
        world: dict[str, np.ndarray] = {}
        for name in names:
            parent = RIG[name][0]
            d = np.array([0.0, 0.0, 0.0, 1.0])
            for axis, joint in BONES.get(name, ()):
                rig_angle = SIGN.get(joint, 1.0) * (ANGLES[joint](t) - OFFSET.get(joint, 0.0))
                d = qmul(d, qaxis(np.array(GLTF[axis]), rig_angle))
            delta[name] = qmul(delta[parent], d) if parent else d
            world[name] = qmul(delta[name], rest_world[name])
            wp = world[parent] if parent else np.array([0.0, 0.0, 0.0, 1.0])
            out[k, names.index(name)] = qmul(qinv(wp), world[name])
    blob = bytearray()
    views: list[gl.BufferView] = []
    accessors: list[gl.Accessor] = []

    def add(a: np.ndarray, kind: str) -> int:
        data = np.ascontiguousarray(a, dtype="<f4")
        views.append(gl.BufferView(buffer=0, byteOffset=len(blob), byteLength=data.nbytes))
        blob.extend(data.tobytes())
        acc = gl.Accessor(bufferView=len(views) - 1, componentType=5126, count=len(data),
                          type=kind)
        if kind == "SCALAR":
            acc.min, acc.max = [float(data.min())], [float(data.max())]
        accessors.append(acc)
        return len(accessors) - 1
    times = add(np.arange(frames) / fps, "SCALAR")
    samplers = [gl.AnimationSampler(input=times, output=add(out[:, b], "VEC4"),
                                    interpolation="LINEAR") for b in range(len(names))]
    channels = [gl.AnimationChannel(sampler=b, target=gl.AnimationChannelTarget(
        node=1 + b, path="rotation")) for b in range(len(names))]
    doc = gl.GLTF2(scene=0, scenes=[gl.Scene(nodes=[0])], nodes=nodes,
                   skins=[gl.Skin(joints=list(range(1, 1 + len(names))))],
                   animations=[gl.Animation(name="dance", samplers=samplers,
                                            channels=channels)],
                   accessors=accessors, bufferViews=views,
                   buffers=[gl.Buffer(byteLength=len(blob))])
    doc.set_binary_blob(bytes(blob))
    doc.save_binary(path)
