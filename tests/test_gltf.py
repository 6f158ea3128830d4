"""glTF export read back: the container with pygltflib, the buffers decoded here by hand
(offsets, float32, the accessor types of the glTF 2.0 spec), each bone's rotation against
the joint stream, and the node hierarchy composed here (matrices, not the exporter's
quaternion product) against the joint positions bvhio computes from the BVH export of the
same motion: two formats, two readers, one skeleton."""

from __future__ import annotations

import math
from pathlib import Path

import bvhio
import numpy as np
import pygltflib as gl
import pytest
from test_bvh import ROTATIONS  # glTF's axes are BVH's: X left, Y up, Z forward

import robot.cli as cli
from robot.config.bundled import DEFAULT_ROBOT
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.motion.takes import read_take

FPS = 30.0
#: Components per element, by accessor type (glTF 2.0, 3.6.2.1).
WIDTH = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def rot(axis: str, a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return {"X": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "Y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "Z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def quat_matrix(x: float, y: float, z: float, w: float) -> np.ndarray:
    """The rotation matrix of a unit quaternion (x, y, z, w)."""
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def read(doc: gl.GLTF2, accessor: int) -> np.ndarray:
    acc = doc.accessors[accessor]
    view = doc.bufferViews[acc.bufferView]
    assert acc.componentType == 5126                      # FLOAT
    start = (view.byteOffset or 0) + (acc.byteOffset or 0)
    n = acc.count * WIDTH[acc.type]
    blob = doc.binary_blob()
    assert blob is not None
    return np.frombuffer(blob, dtype="<f4", count=n, offset=start).reshape(acc.count, -1)


def world_positions(doc: gl.GLTF2, frame: int) -> dict[str, np.ndarray]:
    """Every node's world position at ``frame``, composed from the node tree and the
    animation's sampled values."""
    anim = doc.animations[0]
    local_r = {i: np.eye(3) for i in range(len(doc.nodes))}
    local_t = {i: np.array(n.translation, dtype=float) for i, n in enumerate(doc.nodes)}
    for ch in anim.channels:
        value = read(doc, anim.samplers[ch.sampler].output)[frame].astype(float)
        if ch.target.path == "rotation":
            local_r[ch.target.node] = quat_matrix(*value)
        else:
            local_t[ch.target.node] = value
    out: dict[str, np.ndarray] = {}

    def walk(i: int, r: np.ndarray, p: np.ndarray) -> None:
        pos = p + r @ local_t[i]
        out[doc.nodes[i].name] = pos
        for c in doc.nodes[i].children:
            walk(c, r @ local_r[i], pos)
    walk(doc.scenes[doc.scene].nodes[0], np.eye(3), np.zeros(3))
    return out


def test_glb_round_trips_against_the_stream_and_the_bvh(tmp_path: Path) -> None:
    robot = load_robot(DEFAULT_ROBOT)
    glb, bvh = tmp_path / "walk.glb", tmp_path / "walk.bvh"
    for out in (glb, bvh):
        assert cli.main(["export", "--gait", "walk", "--seconds", "2", "--out", str(out)]) == 0
    frames = int(2 * FPS) + 1
    doc = gl.GLTF2().load(str(glb))
    assert doc is not None and doc.asset.version == "2.0"
    names = [n.name for n in doc.nodes]
    assert set(ROTATIONS) | {"pelvis", "chest", "r_ankle_end", "l_elbow_end"} <= set(names)
    # One skin over every node; its inverse bind matrices undo the rest positions.
    skin = doc.skins[0]
    assert sorted(skin.joints) == list(range(len(doc.nodes)))
    rest = {}

    def rest_walk(i: int, p: np.ndarray) -> None:
        rest[i] = p + np.array(doc.nodes[i].translation)
        for c in doc.nodes[i].children:
            rest_walk(c, rest[i])
    rest_walk(0, np.zeros(3))
    ibm = read(doc, skin.inverseBindMatrices).reshape(-1, 4, 4)   # column-major
    for k, j in enumerate(skin.joints):
        assert ibm[k].T @ np.append(rest[j], 1.0) == pytest.approx([0, 0, 0, 1], abs=1e-6)
    anim = doc.animations[0]
    times = read(doc, anim.samplers[0].input)[:, 0]
    assert len(times) == frames and times == pytest.approx(np.arange(frames) / FPS, abs=1e-6)
    assert doc.accessors[anim.samplers[0].input].max == pytest.approx([(frames - 1) / FPS])
    # Each bone's rotation: the joint stream's angles composed in the robot's order.
    _, qt = GaitEngine(robot, load_gait("walk").params).curves(np.arange(frames) / FPS)
    jn = robot.joint_names
    by_node = {doc.nodes[c.target.node].name: anim.samplers[c.sampler].output
               for c in anim.channels if c.target.path == "rotation"}
    assert set(by_node) == set(ROTATIONS)
    for node, rots in ROTATIONS.items():
        got = read(doc, by_node[node])
        for f in range(0, frames, 6):
            want = np.eye(3)
            for axis, joint in rots:
                want = want @ rot(axis, float(qt[jn.index(joint), f]))
            assert quat_matrix(*got[f].astype(float)) == pytest.approx(want, abs=1e-5), (node, f)
    # The composed hierarchy against bvhio's positions from the BVH of the same motion
    # (centimetres there, metres here), root motion included.
    tree = bvhio.readAsHierarchy(str(bvh))
    for f in range(0, frames, 5):
        tree.loadPose(f)
        want = {j.Name: np.array(j.PositionWorld) / 100 for j, _, _ in tree.layout()}
        got_pos = world_positions(doc, f)
        for name in want:
            assert got_pos[name] == pytest.approx(want[name], abs=2e-5), (name, f)
    assert world_positions(doc, frames - 1)["pelvis"][2] > 0.1     # walked forward (+Z)


def test_gltf_json_embeds_the_same_buffer(tmp_path: Path) -> None:
    glb, js = tmp_path / "a.glb", tmp_path / "a.gltf"
    for out in (glb, js):
        assert cli.main(["export", "--gait", "march", "--seconds", "1", "--fps", "24",
                         "--out", str(out)]) == 0
    text = js.read_text()
    assert '"uri": "data:application/octet-stream;base64,' in text
    a, b = gl.GLTF2().load(str(glb)), gl.GLTF2().load(str(js))
    assert a is not None and b is not None
    b.convert_buffers(gl.BufferFormat.BINARYBLOB)
    assert a.binary_blob() == b.binary_blob()
    assert len(read(b, b.animations[0].samplers[0].input)) == 25


def test_take_exports_as_gltf(tmp_path: Path) -> None:
    take, out = tmp_path / "t.take.jsonl", tmp_path / "t.glb"
    assert cli.main(["walk", "--seconds", "1", "--record", str(take)]) == 0
    assert cli.main(["export", "--take", str(take), "--fps", "50", "--out", str(out)]) == 0
    doc = gl.GLTF2().load(str(out))
    assert doc is not None
    assert doc.animations[0].name == "t"
    rec = read_take(take)
    step = int(rec.header.rate_hz / 50)  # 200 Hz ticks: every 4th is a frame
    got = read(doc, doc.animations[0].samplers[0].input)
    assert len(got) == (len(rec.t) - 1) // step + 1
    rotations = {doc.nodes[c.target.node].name: doc.animations[0].samplers[c.sampler].output
                 for c in doc.animations[0].channels if c.target.path == "rotation"}
    knee = read(doc, rotations["l_knee"])
    names = rec.header.joints
    for f in range(0, len(got), 13):   # a pitch-only joint: (sin(q/2), 0, 0, cos(q/2))
        angle = rec.q[f * step, names.index("l_knee")]
        assert knee[f] == pytest.approx([math.sin(angle / 2), 0, 0, math.cos(angle / 2)],
                                        abs=1e-6)


def test_gltf_refuses_centimetres(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "x.glb"
    assert cli.main(["export", "--units", "cm", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "glTF lengths are metres" in err[0]
    assert not out.exists()
    assert cli.main(["export", "--out", str(tmp_path / "x.fbx")]) == 2
    assert "expected a .bvh, .glb or .gltf" in capsys.readouterr().err


def test_legs_only_robot_has_no_arm_nodes_and_matches_its_bvh(tmp_path: Path) -> None:
    glb, bvh = tmp_path / "legs.glb", tmp_path / "legs.bvh"
    for out in (glb, bvh):
        assert cli.main(["export", "--robot", "biped12-legs", "--gait", "walk", "--seconds",
                         "1", "--out", str(out)]) == 0
    doc = gl.GLTF2().load(str(glb))
    assert doc is not None
    names = {n.name for n in doc.nodes}
    assert not names & {"chest", "r_shoulder", "l_elbow"}
    rotated = {doc.nodes[c.target.node].name for c in doc.animations[0].channels
               if c.target.path == "rotation"}
    assert rotated == {n for n in ROTATIONS if n[2:] in ("hip", "knee", "ankle")}
    tree = bvhio.readAsHierarchy(str(bvh))
    for f in (0, 10, 30):
        tree.loadPose(f)
        got = world_positions(doc, f)
        for j, _, _ in tree.layout():
            assert got[j.Name] == pytest.approx(np.array(j.PositionWorld) / 100, abs=2e-5)
