"""Previs export, second format: the motion as a glTF 2.0 skinned animation (.glb/.gltf).

The same skeleton, axes and root motion as the BVH export (robot/previs/bvh.py): glTF's own
convention is BVH's (Y up, +Z forward, +X left), lengths in metres as glTF requires. Each
bone is a node (its rest offset as the translation), each end site a child node named
``<bone>_end``; one skin lists every node as a joint (inverse bind matrices: the rest
pose), so importers build an armature from it (Blender: File > Import > glTF 2.0).

One animation: the pelvis's translation and every driven bone's rotation, a keyframe per
frame, LINEAR interpolation (slerp). A bone's rotation is the product of its axis
rotations in the order the robot composes them (hip Rz(yaw) Rx(roll) Ry(pitch)), as a
unit quaternion (x, y, z, w) per glTF. Buffers are float32, built here with numpy;
pygltflib writes the container.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pygltflib as gl

from robot.config.robot import RobotConfig
from robot.files.atomic import replacing
from robot.previs.bones import Bone
from robot.previs.bvh import root_motion, skeleton, to_bvh

Array = npt.NDArray[np.float64]
#: Robot axis → glTF unit axis (x fwd → +Z, y left → +X, z up → +Y).
AXIS = {"x": (0.0, 0.0, 1.0), "y": (1.0, 0.0, 0.0), "z": (0.0, 1.0, 0.0)}
SUFFIXES = (".glb", ".gltf")
FLOAT = 5126  # componentType FLOAT (glTF 2.0, accessor.componentType)


def axis_quat(axis: str, angle: Array) -> Array:
    """Quaternions (n, 4) as (x, y, z, w) of rotations ``angle`` [rad] about a robot axis."""
    h = np.asarray(angle, dtype=float) / 2.0
    v = np.asarray(AXIS[axis])
    return np.column_stack([np.outer(np.sin(h), v), np.cos(h)])


def quat_mul(a: Array, b: Array) -> Array:
    """Row-wise Hamilton product of (x, y, z, w) quaternions."""
    ax, ay, az, aw = a.T
    bx, by, bz, bw = b.T
    return np.column_stack([aw * bx + ax * bw + ay * bz - az * by,
                            aw * by - ax * bz + ay * bw + az * bx,
                            aw * bz + ax * by - ay * bx + az * bw,
                            aw * bw - ax * bx - ay * by - az * bz])


def bone_rotations(bone: Bone, names: Sequence[str], q: Array) -> Array:
    """A bone's rotation per frame (n, 4), (x, y, z, w)."""
    out = np.tile([0.0, 0.0, 0.0, 1.0], (len(q), 1))
    for k, (axis, joint) in enumerate(bone.axes):
        if joint is not None:
            out = quat_mul(out, axis_quat(axis, bone.sign(k) * q[:, names.index(joint)]))
    return out


class _Buffer:
    """One binary buffer of float32 accessors, each in its own 4-byte aligned view."""

    def __init__(self) -> None:
        self.blob = bytearray()
        self.views: list[gl.BufferView] = []
        self.accessors: list[gl.Accessor] = []

    def add(self, data: npt.ArrayLike, kind: str, *, bounds: bool = False) -> int:
        a = np.ascontiguousarray(data, dtype="<f4")
        view = gl.BufferView(buffer=0, byteOffset=len(self.blob), byteLength=a.nbytes)
        self.blob += a.tobytes()
        self.views.append(view)
        flat = a.reshape(len(a), -1)
        acc = gl.Accessor(bufferView=len(self.views) - 1, componentType=FLOAT,
                          count=len(a), type=kind)
        if bounds:  # required for animation inputs (and positions)
            acc.min = [float(v) for v in flat.min(axis=0)]
            acc.max = [float(v) for v in flat.max(axis=0)]
        self.accessors.append(acc)
        return len(self.accessors) - 1


def build_gltf(robot: RobotConfig, q: Array, frame_s: float, *, name: str) -> gl.GLTF2:
    """The glTF document for frames ``q`` (n, robot joints) [rad] at ``frame_s`` [s]."""
    bones = skeleton(robot)
    names = robot.joint_names
    nodes: list[gl.Node] = []
    index: dict[str, int] = {}
    rest_world: list[Array] = []
    for b in bones:
        index[b.name] = len(nodes)
        offset = to_bvh(b.offset)
        parent = rest_world[index[b.parent]] if b.parent is not None else np.zeros(3)
        nodes.append(gl.Node(name=b.name, translation=[float(v) for v in offset]))
        rest_world.append(parent + offset)
        if b.parent is not None:
            nodes[index[b.parent]].children.append(index[b.name])
    for b in bones:  # end sites (soles, hands, the chest's top) after every bone
        if b.end is None and any(c.parent == b.name for c in bones):
            continue
        end = to_bvh(b.end or (0.0, 0.0, 0.25 * robot.geometry.thigh))
        nodes[index[b.name]].children.append(len(nodes))
        rest_world.append(rest_world[index[b.name]] + end)
        nodes.append(gl.Node(name=f"{b.name}_end", translation=[float(v) for v in end]))
    buf = _Buffer()
    inverse_bind = np.zeros((len(nodes), 16))
    for i, p in enumerate(rest_world):  # column-major 4x4: a translation by -p
        inverse_bind[i] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -p[0], -p[1], -p[2], 1]
    skin = gl.Skin(name=robot.name, skeleton=0, joints=list(range(len(nodes))),
                   inverseBindMatrices=buf.add(inverse_bind, "MAT4"))
    times = buf.add(np.arange(len(q)) * frame_s, "SCALAR", bounds=True)
    samplers = [gl.AnimationSampler(input=times, interpolation="LINEAR",
                                    output=buf.add(to_bvh(root_motion(robot, q)), "VEC3"))]
    channels = [gl.AnimationChannel(sampler=0, target=gl.AnimationChannelTarget(
        node=0, path="translation"))]
    for b in bones[1:]:
        if all(j is None for _, j in b.axes):
            continue
        samplers.append(gl.AnimationSampler(input=times, interpolation="LINEAR",
                                            output=buf.add(bone_rotations(b, names, q),
                                                           "VEC4")))
        channels.append(gl.AnimationChannel(sampler=len(samplers) - 1,
                                            target=gl.AnimationChannelTarget(
                                                node=index[b.name], path="rotation")))
    doc = gl.GLTF2(asset=gl.Asset(version="2.0", generator="biped export"),
                   scene=0, scenes=[gl.Scene(name=robot.name, nodes=[0])], nodes=nodes,
                   skins=[skin], animations=[gl.Animation(name=name, samplers=samplers,
                                                          channels=channels)],
                   accessors=buf.accessors, bufferViews=buf.views,
                   buffers=[gl.Buffer(byteLength=len(buf.blob))])
    doc.set_binary_blob(bytes(buf.blob))
    return doc


def write_gltf(path: str | Path, robot: RobotConfig, q: Array, frame_s: float, *,
               name: str = "motion") -> int:
    """Write ``q`` as .glb (one binary file) or .gltf (JSON, buffer embedded as a data URI);
    returns the number of frames."""
    path = Path(path)
    doc = build_gltf(robot, q, frame_s, name=name)
    with replacing(path) as temp:
        if path.suffix == ".glb":
            doc.save_binary(str(temp))
        else:
            doc.convert_buffers(gl.BufferFormat.DATAURI)
            doc.save_json(str(temp))
    return len(q)
