"""robot/body/meshes.py: hulls of STL (binary, ASCII) and OBJ files by MuJoCo, the error of
the reduction against a differently written computation (Frank-Wolfe projection onto the
kept vertices, and MuJoCo's own hull volume), refusals in one line, and where a URDF's mesh
references are found."""

from __future__ import annotations

import struct
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robot.body.meshes import (
    DEFAULT_MAX_VERTICES,
    distance_to_surface,
    hull,
    resolve_mesh,
)
from robot.errors import ConfigError
from tests.urdf_files import CUBE_FACES, TETRA, TETRA_FACES, cube, write_obj, write_stl

DUCK = Path(__file__).resolve().parents[2] / "shared" / "robots" / "open_duck_mini_v2"


def _corners(points: tuple[tuple[float, ...], ...], digits: int = 9) -> set[tuple[float, ...]]:
    return {tuple(round(float(c), digits) for c in p) for p in points}


def test_every_format_gives_the_same_hull(tmp_path: Path) -> None:
    verts = cube(0.04, (0.1, -0.2, 0.3))
    files = [write_stl(tmp_path / "b.stl", verts, CUBE_FACES),
             write_stl(tmp_path / "a.stl", verts, CUBE_FACES, ascii_=True),
             write_obj(tmp_path / "c.obj", verts, CUBE_FACES)]
    want = _corners(tuple(tuple(v * (2.0, 1.0, 0.5)) for v in verts), 6)  # binary STL: float32
    for f in files:
        h = hull(f, scale=(2.0, 1.0, 0.5))
        assert _corners(h.vertices, 6) == want, f
        assert (h.full_vertices, h.error, h.volume_lost) == (8, 0.0, 0.0)
    tetra = hull(write_stl(tmp_path / "t.stl", TETRA * 0.05, TETRA_FACES, ascii_=True))
    assert _corners(tetra.vertices) == _corners(tuple(tuple(v) for v in TETRA * 0.05))  # ASCII: exact


def test_distance_to_a_triangle_against_sampling() -> None:
    tri = np.array([[[0.0, 0.0, 0.0], [0.03, 0.0, 0.0], [0.01, 0.02, 0.0]]])
    pts = np.random.default_rng(3).uniform(-0.03, 0.06, size=(40, 3))
    u, v = np.meshgrid(np.linspace(0, 1, 401), np.linspace(0, 1, 401))
    keep = u + v <= 1.0
    samples = tri[0, 0] + u[keep, None] * (tri[0, 1] - tri[0, 0]) + v[keep, None] * (tri[0, 2] - tri[0, 0])
    brute = np.array([np.linalg.norm(samples - p, axis=1).min() for p in pts])
    np.testing.assert_allclose(distance_to_surface(pts, tri), brute, atol=1e-4 * 0.03)
    assert np.all(distance_to_surface(pts, tri) <= brute + 1e-12)


def _frank_wolfe(p: np.ndarray, verts: np.ndarray, steps: int = 4000) -> tuple[float, float]:
    """Lower and upper bounds of the distance from ``p`` to the hull of ``verts``: the
    Frank-Wolfe iterate's distance (a point of the hull) and its duality gap's plane."""
    x = verts[np.argmin(np.linalg.norm(verts - p, axis=1))].copy()
    lower = 0.0
    for _ in range(steps):
        g = x - p
        s = verts[np.argmin(verts @ g)]
        n = -g / max(np.linalg.norm(g), 1e-300)
        lower = max(lower, float(n @ p - np.max(verts @ n)))
        d = s - x
        t = float(np.clip(-(g @ d) / max(d @ d, 1e-300), 0.0, 1.0))
        x = x + t * d
    return lower, float(np.linalg.norm(x - p))


def _read_binary_stl(path: Path) -> np.ndarray:
    data = path.read_bytes()
    (n,) = struct.unpack("<I", data[80:84])
    return np.array([struct.unpack("<3f", data[84 + 50 * i + 12 * k:96 + 50 * i + 12 * k])
                     for i in range(n) for k in (1, 2, 3)], float)


def _mujoco_volume(points: np.ndarray) -> float:
    spec = mujoco.MjSpec()
    spec.add_mesh(name="m", uservert=np.ravel(points).tolist())
    spec.worldbody.add_body().add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname="m", density=1.0)
    return float(spec.compile().body_mass[1])


def test_the_reduction_and_its_stated_error_on_a_real_mesh() -> None:
    path = DUCK / "left_roll_to_pitch.stl"
    raw = _read_binary_stl(path)
    h = hull(path)
    kept = np.array(h.vertices)
    assert len(kept) == DEFAULT_MAX_VERTICES < h.full_vertices
    assert _corners(h.vertices) <= _corners(tuple(map(tuple, raw)))  # the file's own vertices
    whole = hull(path, max_vertices=100000)
    assert len(whole.vertices) == h.full_vertices and whole.error == 0.0
    dropped = np.array([v for v in whole.vertices if tuple(np.round(v, 9)) not in _corners(h.vertices)])
    bounds = np.array([_frank_wolfe(p, kept, steps=300) for p in dropped])
    close = dropped[bounds[:, 1] >= bounds[:, 0].max()]  # the points that may be the farthest
    fine = np.array([_frank_wolfe(p, kept) for p in close])
    lo, hi = fine[:, 0].max(), fine[:, 1].max()
    assert hi - lo < 2e-6  # the oracle is tight to 2 um
    assert lo - 1e-9 <= h.error <= hi + 1e-9
    assert h.error < 0.0015  # the module's claim for the Open Duck's parts: at most 1.1 mm
    lost = 1.0 - _mujoco_volume(kept) / _mujoco_volume(raw)
    assert h.volume_lost == pytest.approx(lost, abs=1e-9)
    assert f"{len(kept)} of its {h.full_vertices} hull vertices" in h.note("x.stl")


def test_meshes_that_are_refused(tmp_path: Path) -> None:
    cases = {
        "leg.dae": ("<COLLADA/>", "mesh format .dae is not read (STL or OBJ, as MuJoCo); convert it to STL"),
        "leg.ply": ("ply", "mesh format .ply is not read"),
        "junk.stl": ("not a mesh at all", "not an STL file"),
        "few.obj": ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "the mesh has 3 vertices, a solid needs 4 or more"),
        "flat.obj": ("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n", "MuJoCo cannot make a hull of the mesh"),
    }
    for name, (text, words) in cases.items():
        (tmp_path / name).write_text(text)
        with pytest.raises(ConfigError) as err:
            hull(tmp_path / name)
        assert str(err.value).startswith(f"{tmp_path / name}: ") and words in str(err.value)
        assert "\n" not in str(err.value)
    with pytest.raises(ConfigError, match="cannot read the mesh"):
        hull(tmp_path / "absent.stl")


def test_where_mesh_references_are_found(tmp_path: Path) -> None:
    pkg = tmp_path / "ws" / "my_description"
    target = write_stl(pkg / "meshes" / "Thigh.STL", cube(0.01), CUBE_FACES)
    urdf_dir = pkg / "urdf"
    urdf_dir.mkdir()
    ref = "package://my_description/meshes/Thigh.STL"
    assert resolve_mesh(ref, base_dir=urdf_dir)[0] == target  # a ROS package's layout
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    found, tried, _ = resolve_mesh(ref, base_dir=elsewhere)
    assert found is None and elsewhere / "meshes" / "Thigh.STL" in tried
    for mesh_dir in (tmp_path / "ws", pkg, pkg / "meshes"):
        assert resolve_mesh(ref, base_dir=elsewhere, mesh_dir=mesh_dir)[0] == target
    found, _, folded = resolve_mesh("package://my_description/Meshes/thigh.stl", base_dir=elsewhere,
                                    mesh_dir=tmp_path / "ws")
    assert found == target and folded
    assert resolve_mesh(f"file://{target}", base_dir=elsewhere)[0] == target
    assert resolve_mesh("../meshes/Thigh.STL", base_dir=urdf_dir)[0] == urdf_dir / "../meshes/Thigh.STL"
    assert resolve_mesh("../MESHES/thigh.stl", base_dir=urdf_dir)[1:] != ([], False)
    assert resolve_mesh("../MESHES/thigh.stl", base_dir=urdf_dir)[2]
