"""robot/body/urdf_read.py against MuJoCo's own URDF parser, on URDFs written in the style
of onshape-to-robot, fusion2urdf and the SolidWorks exporter (tests/urdf_files.py says
how the copy MuJoCo reads works around its parser).

The oracle: every link's (and every fused link's frame's) world position and rotation at
the zero pose and at random joint angles, the hinge axes and anchors in the world, the
total mass (MuJoCo without fusing), the fused links' mass, centre of mass and inertia
(MuJoCo fusing them itself), and where each collision shape is in the world.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from robot.body.tree import BodyTree, quat_to_matrix
from robot.body.urdf_read import read_urdf
from tests.urdf_files import fusion_style, mujoco_copy, onshape_style, solidworks_style

STYLES = {"onshape": onshape_style, "fusion": fusion_style, "solidworks": solidworks_style}


def _oracle(urdf: Path, refs: dict[str, Path], tmp: Path, *, fuse: bool = False) -> mujoco.MjModel:
    out = mujoco_copy(urdf, refs, tmp / ("fused.urdf" if fuse else "oracle.urdf"), fuse=fuse)
    return mujoco.MjModel.from_xml_path(str(out))


def _world_frames(tree: BodyTree, q: dict[str, float]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Every link and frame of the tree in the world: name → (position, rotation)."""
    pos, rot = tree.poses(q)
    out = {}
    for i, link in enumerate(tree.links):
        out[link.name] = (pos[i], rot[i])
        for f in link.frames:
            out[f.name] = (pos[i] + rot[i] @ np.asarray(f.pos), rot[i] @ quat_to_matrix(f.quat))
    return out


@pytest.mark.parametrize("style", STYLES)
def test_kinematics_and_mass_match_mujoco(style: str, tmp_path: Path) -> None:
    urdf, refs = STYLES[style](tmp_path)
    tree, _ = read_urdf(urdf)
    model = _oracle(urdf, refs, tmp_path)
    data = mujoco.MjData(model)
    bodies = [model.body(b).name for b in range(1, model.nbody)]
    assert sorted(_world_frames(tree, {})) == sorted(bodies)
    assert tree.mass == pytest.approx(float(model.body_mass.sum()), abs=1e-12)
    hinges = [link.joint for link in tree.links if link.joint]
    assert sorted(h.name for h in hinges) == sorted(model.joint(j).name for j in range(model.njnt))
    rng = np.random.default_rng(31)
    for trial in range(5):
        q = {h.name: (0.0 if trial == 0 else float(rng.uniform(-2.0, 2.0))) for h in hinges}
        for name, angle in q.items():
            data.qpos[model.joint(name).qposadr[0]] = angle
        mujoco.mj_kinematics(model, data)
        mine = _world_frames(tree, q)
        for name in bodies:
            p, r = mine[name]
            np.testing.assert_allclose(p, data.body(name).xpos, atol=1e-9, err_msg=name)
            np.testing.assert_allclose(r, data.body(name).xmat.reshape(3, 3), atol=1e-9, err_msg=name)
        pos, rot = tree.poses(q)
        for h in hinges:
            i = tree.joint_link[h.name]
            np.testing.assert_allclose(rot[i] @ np.asarray(h.axis), data.joint(h.name).xaxis, atol=1e-9)
            np.testing.assert_allclose(pos[i] + rot[i] @ np.asarray(h.pos), data.joint(h.name).xanchor,
                                       atol=1e-9)


@pytest.mark.parametrize("style", STYLES)
def test_fused_inertials_match_mujoco_fusing(style: str, tmp_path: Path) -> None:
    """MuJoCo's fusestatic combines the fixed-joint links itself: same bodies, masses,
    centres of mass and inertia matrices (parallel axis theorem, rotations)."""
    urdf, refs = STYLES[style](tmp_path)
    tree, _ = read_urdf(urdf)
    model = _oracle(urdf, refs, tmp_path, fuse=True)
    assert sorted(link.name for link in tree.links) == sorted(
        model.body(b).name for b in range(1, model.nbody))
    for link in tree.links:
        body = model.body(link.name)
        assert link.inertial is not None
        assert link.inertial.mass == pytest.approx(float(body.mass[0]), rel=1e-12)
        np.testing.assert_allclose(link.inertial.com, body.ipos, atol=1e-12)
        r = quat_to_matrix(body.iquat)
        np.testing.assert_allclose(link.inertial.matrix(), r @ np.diag(body.inertia) @ r.T,
                                   atol=1e-12, err_msg=link.name)


@pytest.mark.parametrize("style", STYLES)
def test_collision_shapes_sit_where_mujoco_puts_them(style: str, tmp_path: Path) -> None:
    urdf, refs = STYLES[style](tmp_path)
    tree, _ = read_urdf(urdf)
    model = _oracle(urdf, refs, tmp_path)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(5)
    q = {link.joint.name: float(rng.uniform(-1.0, 1.0)) for link in tree.links if link.joint}
    for name, angle in q.items():
        data.qpos[model.joint(name).qposadr[0]] = angle
    mujoco.mj_kinematics(model, data)
    mesh_points, prims = [], []
    for g in range(model.ngeom):
        world = data.geom_xpos[g] + model.geom_size[g] * 0
        xmat = data.geom_xmat[g].reshape(3, 3)
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            m = model.geom_dataid[g]
            verts = model.mesh_vert[model.mesh_vertadr[m]:model.mesh_vertadr[m] + model.mesh_vertnum[m]]
            mesh_points.append(world + verts.astype(float) @ xmat.T)
        else:
            prims.append((model.geom_type[g], world, xmat, model.geom_size[g]))
    pool = np.concatenate(mesh_points) if mesh_points else np.zeros((0, 3))
    pos, rot = tree.poses(q)
    hulls = 0
    for i, link in enumerate(tree.links):
        for s in link.shapes:
            r = rot[i] @ quat_to_matrix(s.quat)
            p = pos[i] + rot[i] @ np.asarray(s.pos)
            if s.kind == "hull":
                hulls += 1
                for v in p + np.asarray(s.vertices) @ r.T:
                    assert np.linalg.norm(pool - v, axis=1).min() < 1e-6  # MuJoCo keeps float32
                continue
            match = [pr for pr in prims if np.allclose(pr[1], p, atol=1e-9)]
            assert len(match) == 1, s.name
            _, _, xmat, size = match[0]
            np.testing.assert_allclose(xmat, r, atol=1e-9)
            np.testing.assert_allclose(size[:len(s.size)], s.size, atol=1e-12)
    assert hulls == len(mesh_points) and len(prims) == sum(
        s.kind != "hull" for link in tree.links for s in link.shapes)


def test_what_each_exporter_writes_is_taken(tmp_path: Path) -> None:
    onshape, _ = onshape_style(tmp_path / "a")
    tree, warnings = read_urdf(onshape)
    assert [link.name for link in tree.links][0] == "trunk"
    trunk = tree.links[0]
    assert [f.name for f in trunk.frames] == ["imu"]
    knee = tree.links[tree.joint_link["left_knee"]].joint
    assert knee is not None and knee.range == (-0.1, 2.4) and (knee.effort, knee.velocity) == (2.9, 6.2)
    assert warnings == []
    fusion, _ = fusion_style(tmp_path / "b")
    tree, warnings = read_urdf(fusion)
    assert tree.links[0].name == "base_link" and [f.name for f in tree.links[0].frames] == ["body_1"]
    wheel = tree.links[tree.joint_link["Revolute_3"]].joint
    assert wheel is not None and wheel.range is None and wheel.effort is None
    np.testing.assert_allclose(wheel.axis, (0.0, 0.6, 0.8))
    assert all(s.kind == "hull" and s.note.startswith("convex hull of") for s in tree.links[0].shapes)
    sw, _ = solidworks_style(tmp_path / "c")
    tree, warnings = read_urdf(sw)
    j1 = tree.links[tree.joint_link["joint1"]].joint
    assert j1 is not None and j1.effort is None and j1.velocity is None
    assert len(warnings) == 2 and all("differs in case" in w for w in warnings)
    assert "'package://asm/meshes/Link1.STL'" in warnings[1] and "link1.stl" in warnings[1]


def test_mesh_dir_finds_package_meshes_elsewhere(tmp_path: Path) -> None:
    urdf, _ = fusion_style(tmp_path / "src")
    moved = tmp_path / "elsewhere" / "robot.urdf"
    moved.parent.mkdir()
    moved.write_text(urdf.read_text())
    with pytest.raises(Exception, match="not found"):
        read_urdf(moved)
    for mesh_dir in (tmp_path / "src", tmp_path / "src" / "bot_description",
                     tmp_path / "src" / "bot_description" / "meshes"):
        tree, _ = read_urdf(moved, mesh_dir=mesh_dir)
        assert sum(s.kind == "hull" for link in tree.links for s in link.shapes) == 5
