"""Reading a glTF 2.0 skinned animation (.glb / .gltf) into a Rig (robot/previs/rig.py):
ours or Blender's exporter's (which gives bones rest rotations and resamples every frame).

The first skin's joints are the bones (a joint's parent: its nearest ancestor that is a
joint; the nodes above the root bone, e.g. Blender's armature object, fold into the root's
rest); the first animation's rotation and translation channels on them are sampled at a
uniform frame rate, the smallest key spacing of the animation (LINEAR: slerp, STEP: the key
before, CUBICSPLINE: its value through the keys). An animation of LINEAR tracks only is
*sampled* (Blender bakes every frame so; ``Rig.sampled``: the import's spline recovers what
lies between the frames); one with a CUBICSPLINE or STEP track is keyframes, whose curves
the import follows with the monotone cubic (robot/motion/interp.py). Node scale is taken as 1. pygltflib reads
the container; accessors are decoded here with numpy (float, or normalised integers as the
spec allows for rotations).
"""

from __future__ import annotations

import os
import struct
import warnings
from pathlib import Path
from urllib.parse import unquote, urlsplit

import numpy as np
import pygltflib as gl

from robot.errors import ConfigError
from robot.previs.rig import Array, Rig, nominal_frame_s
from robot.previs.rotations import quat_matrix

#: accessor.componentType → (numpy dtype, divisor of a normalised integer).
COMPONENTS = {5126: ("<f4", 0.0), 5120: ("<i1", 127.0), 5121: ("<u1", 255.0),
              5122: ("<i2", 32767.0), 5123: ("<u2", 65535.0)}
WIDTH = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}
#: Bytes of a .glb's header (magic, version, total length).
GLB_HEADER = 12
#: Most frames resampled (an hour at 60 fps).
MAX_FRAMES = 216_000


def _accessor(doc: gl.GLTF2, blob: bytes, index: int, where: str) -> Array:
    acc = doc.accessors[index]
    if acc.componentType not in COMPONENTS or acc.type not in WIDTH or acc.bufferView is None:
        raise ConfigError(f"{where}: accessor {index}: unsupported {acc.type} of component "
                          f"type {acc.componentType}")
    dtype, scale = COMPONENTS[acc.componentType]
    view = doc.bufferViews[acc.bufferView]
    width = WIDTH[acc.type]
    size = np.dtype(dtype).itemsize
    stride = view.byteStride or width * size
    start = (view.byteOffset or 0) + (acc.byteOffset or 0)
    need = start + stride * (acc.count - 1) + width * size
    if need > len(blob):
        raise ConfigError(f"{where}: accessor {index} runs past the end of its buffer")
    raw = np.lib.stride_tricks.as_strided(
        np.frombuffer(blob, dtype=np.uint8, count=need - start, offset=start),
        shape=(acc.count, width * size), strides=(stride, 1))
    out = np.frombuffer(raw.copy().tobytes(), dtype=dtype).reshape(acc.count, width)
    val = out.astype(float)
    if scale:
        val = np.maximum(val / scale, -1.0)
    if not np.all(np.isfinite(val)):
        raise ConfigError(f"{where}: accessor {index} holds a value that is not finite")
    return val


def _rest(node: gl.Node) -> tuple[Array, Array]:
    """A node's rest rotation (3, 3) and translation (3,)."""
    if node.matrix:
        m = np.asarray(node.matrix, dtype=float).reshape(4, 4).T   # column-major
        r = m[:3, :3] / np.linalg.norm(m[:3, :3], axis=0)
        return r, m[:3, 3]
    r = quat_matrix([node.rotation])[0] if node.rotation else np.eye(3)
    return r, np.asarray(node.translation or [0.0, 0.0, 0.0], dtype=float)


def _slerp(t: Array, times: Array, q: Array) -> Array:
    """Quaternions (x, y, z, w) at ``t`` by slerp between the keys (shortest arc)."""
    i = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    h = np.where(times[i + 1] > times[i], times[i + 1] - times[i], 1.0)
    s = np.clip((t - times[i]) / h, 0.0, 1.0)[:, None]
    a, b = q[i], q[i + 1]
    d = np.sum(a * b, axis=1, keepdims=True)
    b = np.where(d < 0, -b, b)
    d = np.clip(np.abs(d), -1.0, 1.0)
    w = np.arccos(d)
    small = w < 1e-6
    sw = np.where(small, 1.0, np.sin(w))
    ka = np.where(small, 1.0 - s, np.sin((1.0 - s) * w) / sw)
    kb = np.where(small, s, np.sin(s * w) / sw)
    out = ka * a + kb * b
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def _sample(kind: str, t: Array, times: Array, values: Array, rotation: bool) -> Array:
    if kind == "CUBICSPLINE":
        values = values[1::3]                       # (in-tangent, value, out-tangent)
    if len(times) == 1:
        return np.repeat(values[:1], len(t), axis=0)
    if kind == "STEP":
        i = np.clip(np.searchsorted(times, t + 1e-9, side="right") - 1, 0, len(times) - 1)
        return values[i]
    if rotation:
        return _slerp(t, times, values)
    return np.column_stack([np.interp(t, times, values[:, c]) for c in range(values.shape[1])])


def check_glb(p: Path) -> None:
    """ConfigError unless the .glb's lengths (the header's total, each chunk's) fit the
    file: read before pygltflib, which reads as many bytes as a chunk says it holds."""
    try:
        size = p.stat().st_size
        with p.open("rb") as f:
            head = f.read(GLB_HEADER)
            if len(head) < GLB_HEADER or head[:4] != b"glTF":
                return                                  # pygltflib says what is wrong
            total = struct.unpack_from("<I", head, 8)[0]
            if total != size:
                raise ConfigError(f"{p}: its header says {total} bytes; the file has {size}")
            at = GLB_HEADER
            while at < size:
                f.seek(at)
                chunk = f.read(8)
                if len(chunk) < 8:
                    raise ConfigError(f"{p}: the chunk at byte {at} is cut short")
                n, kind = struct.unpack("<I4s", chunk)
                if n > size - at - 8:
                    name = kind.rstrip(b"\0").decode("ascii", "replace")
                    raise ConfigError(f"{p}: its {name} chunk at byte {at} says {n} bytes; "
                                      f"{size - at - 8} follow in the file")
                at += 8 + n
    except OSError as e:
        raise ConfigError(f"{p}: cannot read it: {e.strerror or e}") from None


def check_uris(doc: gl.GLTF2, p: Path) -> None:
    """ConfigError unless every buffer and image uri is a data: URI or a file inside the
    glTF's folder (a relative path that stays there, links resolved): nothing is read
    from anywhere else (an absolute path, another scheme, ``..`` out of the folder)."""
    folder = os.path.realpath(p.parent)
    for kind, items in (("buffers", doc.buffers), ("images", doc.images)):
        for i, item in enumerate(items or []):
            uri = item.uri
            if uri is None or uri.startswith("data:"):
                continue
            where = f"{p}: {kind}[{i}].uri {uri[:60]!r}"
            path = unquote(uri)
            why = ("has a scheme other than data:" if urlsplit(uri).scheme else
                   "is an absolute path" if os.path.isabs(path) or path.startswith("\\") else
                   "leaves the glTF's folder" if os.path.commonpath(
                       [folder, os.path.realpath(os.path.join(folder, path))]) != folder
                   else None)
            if why:
                raise ConfigError(f"{where}: {why}; expected a data: URI or a file in "
                                  f"{p.parent} (a relative path)")


def read_gltf(path: str | Path) -> Rig:
    p = Path(path)
    src = str(p)
    if p.suffix.lower() == ".glb":
        check_glb(p)
    try:
        doc = gl.GLTF2().load(src)
    except FileNotFoundError:
        raise ConfigError(f"{p}: file not found") from None
    except Exception as e:  # noqa: BLE001 - pygltflib raises anything on a bad file
        raise ConfigError(f"{p}: not a readable glTF file: {e}") from None
    if doc is None or not doc.skins or not doc.animations:
        raise ConfigError(f"{p}: no skin or no animation; expected a skinned, animated "
                          "glTF (Blender: File > Export > glTF 2.0 with the armature)")
    check_uris(doc, p)
    blob = doc.binary_blob()
    if blob is None:
        with warnings.catch_warnings():     # "will leave x.bin orphaned": we write nothing
            warnings.simplefilter("ignore", UserWarning)
            doc.convert_buffers(gl.BufferFormat.BINARYBLOB)
        blob = doc.binary_blob() or b""
    joints = list(doc.skins[0].joints)
    up: dict[int, int] = {c: i for i, n in enumerate(doc.nodes) for c in n.children}
    order: list[int] = []

    def bone_parent(node: int) -> int:
        a = up.get(node)
        while a is not None and a not in joints:
            a = up.get(a)
        return -1 if a is None else a
    pending = list(joints)
    while pending:   # parents first
        ready = [j for j in pending if bone_parent(j) == -1 or bone_parent(j) in order]
        if not ready:
            raise ConfigError(f"{p}: the skin's joints form a cycle")
        order += ready
        pending = [j for j in pending if j not in ready]
    roots = [j for j in order if bone_parent(j) == -1]
    if len(roots) != 1:
        raise ConfigError(f"{p}: the skin has {len(roots)} root bones; expected one")
    anim = doc.animations[0]
    channels = {(c.target.node, c.target.path): anim.samplers[c.sampler]
                for c in anim.channels if c.target.node in joints}
    inputs = [_accessor(doc, blob, s.input, src)[:, 0] for s in channels.values()]
    if not inputs:
        raise ConfigError(f"{p}: animation {anim.name!r} moves none of the skin's bones")
    step = min((float(np.min(np.diff(t))) for t in inputs if len(t) > 1), default=1 / 30)
    start = min(float(t[0]) for t in inputs)
    stop = max(float(t[-1]) for t in inputs)
    n = int(round((stop - start) / step)) + 1 if step > 0 else 1
    if n > MAX_FRAMES:
        raise ConfigError(f"{p}: {n} frames at {1 / step:g} fps; at most {MAX_FRAMES}")
    t = np.asarray(start + np.arange(n) * step, dtype=np.float64)
    index = {node: b for b, node in enumerate(order)}
    rest = np.empty((len(order), 3, 3))
    offsets = np.empty((len(order), 3))
    local = np.empty((n, len(order), 3, 3))
    above = np.eye(3)
    a = up.get(roots[0])
    while a is not None:                 # the nodes above the root bone
        above = _rest(doc.nodes[a])[0] @ above
        a = up.get(a)
    root = np.zeros((n, 3))
    for b, node in enumerate(order):
        rest[b], offsets[b] = _rest(doc.nodes[node])
        rot = channels.get((node, "rotation"))
        if rot is None:
            local[:, b] = rest[b]
        else:
            times = _accessor(doc, blob, rot.input, src)[:, 0]
            quats = _sample(rot.interpolation or "LINEAR", t, times,
                            _accessor(doc, blob, rot.output, src), rotation=True)
            local[:, b] = quat_matrix(quats)
        if b == 0:
            move = channels.get((node, "translation"))
            root[:] = offsets[0] if move is None else _sample(
                move.interpolation or "LINEAR", t, _accessor(doc, blob, move.input, src)[:, 0],
                _accessor(doc, blob, move.output, src), rotation=False)
            root = root @ above.T
    rest[0] = above @ rest[0]
    local[:, 0] = above @ local[:, 0]
    names = tuple(doc.nodes[j].name or f"node{j}" for j in order)
    parents = tuple(index[bone_parent(j)] if bone_parent(j) != -1 else -1 for j in order)
    leaf_ends = tuple((index[up[c]], tuple(float(v) for v in _rest(doc.nodes[c])[1]))
                      for c in range(len(doc.nodes)) if c not in joints and up.get(c) in index)
    sampled = all((s.interpolation or "LINEAR") == "LINEAR" for s in channels.values())
    return Rig.from_local(names, parents, offsets, rest, local, root, nominal_frame_s(step),
                          ends=leaf_ends, source=src, sampled=sampled)  # type: ignore[arg-type]
