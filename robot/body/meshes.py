"""A collision mesh as the simulation sees it: its convex hull, computed by MuJoCo itself.

MuJoCo collides a mesh geom by the convex hull of its vertices, so the hull is exactly
what it would simulate; the importer keeps the hull's vertices (as a ``Shape`` of kind
"hull"), reduced to at most ``max_vertices`` with MuJoCo's own ``maxhullvert`` (qhull adds
the farthest vertex first, so the kept hull is the best of that size qhull finds), and
states what the reduction lost: the largest distance of a dropped hull vertex from the
kept hull (the Hausdorff distance of the two hulls, since the kept one lies inside the
whole one) [m], and the volume lost [fraction].

Formats: what MuJoCo itself loads, STL (binary and ASCII) and OBJ; any other is refused
in one line. Paths: ``resolve_mesh`` finds a URDF's mesh reference on disk.
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from robot.body.tree import Array, Vec3, quat_to_matrix
from robot.errors import ConfigError

log = logging.getLogger(__name__)

MESH_SUFFIXES = (".stl", ".obj")
#: Hull vertices kept by default. On the Open Duck Mini v2's 17 meshes (parts of 20-150
#: mm, hulls of 12-456 vertices) 64 keep a dropped vertex at most 1.1 mm (median 0.2 mm)
#: outside the kept hull and lose at most 1.4 % of its volume (32: 2.7 mm and 6 %; 128:
#: 0.6 mm): below a printed part's tolerance, while MuJoCo's convex collision (a support
#: function hill-climbing the hull's graph) costs less the fewer vertices, and a robot
#: file carries 64 vertices a shape, not hundreds.
DEFAULT_MAX_VERTICES = 64
_FLOAT = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_ASCII_VERTEX = re.compile(rf"vertex\s+({_FLOAT})\s+({_FLOAT})\s+({_FLOAT})")


@dataclass(frozen=True)
class Hull:
    """A mesh's convex hull, reduced. vertices: in the mesh file's frame, scaled [m];
    full_vertices: how many the whole hull has; error: largest distance of a dropped hull
    vertex from the kept hull [m]; volume_lost: 1 - kept volume / whole volume."""

    vertices: tuple[Vec3, ...]
    full_vertices: int
    error: float
    volume_lost: float

    def note(self, source: str) -> str:
        return (f"convex hull of {source}: {len(self.vertices)} of its {self.full_vertices} "
                f"hull vertices kept, a dropped vertex at most {self.error * 1000:.2f} mm "
                f"outside, {self.volume_lost * 100:.2f} % of the volume lost")


def read_vertices(path: Path, *, scale: Vec3 = (1.0, 1.0, 1.0)) -> Array:
    """The distinct vertices (n, 3) of an STL (binary or ASCII) or OBJ file, times
    ``scale`` [m]. Raises ConfigError naming the file."""
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise ConfigError(f"{path}: mesh format {path.suffix or '(none)'} is not read "
                          f"(STL or OBJ, as MuJoCo); convert it to STL (Blender, MeshLab)")
    try:
        data = path.read_bytes()
    except OSError as err:
        raise ConfigError(f"{path}: cannot read the mesh: {err.strerror}") from err
    if suffix == ".obj":
        pts = _obj_vertices(data)
    elif len(data) >= 84 and len(data) == 84 + 50 * int.from_bytes(data[80:84], "little"):
        rows = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)),
                                                   ("a", "<u2")]), offset=84)
        pts = rows["v"].reshape(-1, 3).astype(float)
    else:
        text = data.decode("latin-1")
        if not text.lstrip().startswith("solid"):
            raise ConfigError(f"{path}: not an STL file (neither binary nor ASCII STL)")
        pts = np.array([[float(x) for x in m.groups()] for m in _ASCII_VERTEX.finditer(text)])
    pts = pts.reshape(-1, 3)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if len(pts) < 4:
        raise ConfigError(f"{path}: the mesh has {len(pts)} vertices, a solid needs 4 or more")
    return np.unique(pts, axis=0) * np.asarray(scale, float)


def _obj_vertices(data: bytes) -> Array:
    rows = []
    for line in data.decode("latin-1").splitlines():
        parts = line.split()
        if len(parts) >= 4 and parts[0] == "v":
            rows.append([float(x) for x in parts[1:4]])
    return np.array(rows, float)


def _hull_of(points: Array, max_vertices: int, path: Path) -> tuple[Array, Array]:
    """MuJoCo's hull of ``points``: indices of its vertices and its faces (k, 3)."""
    spec = mujoco.MjSpec()
    spec.add_mesh(name="m", uservert=points.ravel().tolist(), maxhullvert=max_vertices)
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname="m")
    try:
        model = spec.compile()
    except ValueError as err:
        first = str(err).splitlines()[0].removeprefix("Error: ")
        raise ConfigError(f"{path}: MuJoCo cannot make a hull of the mesh: {first}") from err
    start, count = model.mesh_vertadr[0], model.mesh_vertnum[0]
    back = model.mesh_pos[0] + model.mesh_vert[start:start + count] @ quat_to_matrix(
        model.mesh_quat[0]).T
    if count != len(points) or np.abs(back - points).max() > 1e-5 * (1 + np.abs(points).max()):
        raise ConfigError(f"{path}: MuJoCo reordered the mesh's vertices; cannot read its hull")
    graph = model.mesh_graph[model.mesh_graphadr[0]:]
    nv, nf = int(graph[0]), int(graph[1])
    ids = np.asarray(graph[2 + nv:2 + 2 * nv], int)
    faces = np.asarray(graph[2 + 3 * nv + 3 * nf:2 + 3 * nv + 6 * nf], int).reshape(nf, 3)
    return ids, faces


def _volume(points: Array, faces: Array) -> float:
    centre = points[faces].reshape(-1, 3).mean(axis=0)
    a, b, c = (points[faces[:, k]] - centre for k in range(3))
    return abs(float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum())) / 6.0


def _segment_distance(p: Array, a: Array, b: Array) -> Array:
    ab = b - a
    t = np.clip(np.einsum("ijk,ijk->ij", p - a, ab) / np.maximum(
        np.einsum("ijk,ijk->ij", ab, ab), 1e-300), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def distance_to_surface(points: Array, corners: Array) -> Array:
    """Distance of each point (m, 3) to the nearest of the triangles (k, 3, 3) [m]: in the
    triangle's plane where the point projects inside it, else to its nearest edge."""
    p = points[:, None, :]
    a, b, c = (corners[None, :, k, :] for k in range(3))
    n = np.cross(b - a, c - a)
    n = n / np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-300)
    height = np.einsum("ijk,ijk->ij", p - a, n)
    q = p - height[..., None] * n
    inside = np.ones(height.shape, bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ijk,ijk->ij", np.cross(v - u, q - u), n) >= 0.0
    edges = np.minimum.reduce([_segment_distance(p, a, b), _segment_distance(p, b, c),
                               _segment_distance(p, c, a)])
    return np.where(inside, np.abs(height), edges).min(axis=1)


def hull(path: Path, *, scale: Vec3 = (1.0, 1.0, 1.0),
         max_vertices: int = DEFAULT_MAX_VERTICES) -> Hull:
    """The convex hull of the mesh file at ``path`` times ``scale``, at most
    ``max_vertices`` (>= 4) vertices, with the error of the reduction (see ``Hull``)."""
    if max_vertices < 4:
        raise ConfigError(f"max_vertices: a hull needs 4 or more, not {max_vertices}")
    points = read_vertices(path, scale=scale)
    full_ids, full_faces = _hull_of(points, -1, path)
    if len(full_ids) <= max_vertices:
        ids, faces = full_ids, full_faces
    else:
        ids, faces = _hull_of(points, max_vertices, path)
    dropped = np.setdiff1d(full_ids, ids)
    error = float(distance_to_surface(points[dropped], points[faces]).max()) if len(dropped) else 0.0
    whole = _volume(points, full_faces)
    lost = 1.0 - _volume(points, faces) / whole if whole > 0 else 0.0
    verts = tuple((float(x), float(y), float(z)) for x, y, z in points[np.sort(ids)])
    return Hull(vertices=verts, full_vertices=len(full_ids), error=error, volume_lost=max(lost, 0.0))


def _walk(anchor: Path, parts: list[str]) -> tuple[Path | None, bool]:
    """``anchor / parts``, each part matched exactly or else ignoring case: (path or None,
    whether a case differed)."""
    here, folded = anchor, False
    for part in parts:
        if part in ("", "."):
            continue
        nxt = here / part
        if not nxt.exists():
            try:
                same = [e for e in here.iterdir() if e.name.lower() == part.lower()]
            except OSError:
                return None, folded
            if len(same) != 1:
                return None, folded
            nxt, folded = same[0], True
        here = nxt
    return (here, folded) if here.is_file() else (None, folded)


def mesh_candidates(ref: str, *, base_dir: Path, mesh_dir: Path | None) -> list[Path]:
    """Where a URDF's mesh ``ref`` may be, in order: ``package://PKG/rest`` under
    ``mesh_dir`` as DIR/PKG/rest, DIR/rest, DIR/<file name>, then in a folder named PKG above
    the URDF, PKG/rest beside the URDF (onshape-to-robot's package://assets/...), rest in
    the URDF's parent folder (a ROS package's urdf/ and meshes/), beside it, and the file
    name beside it; ``file://`` and plain paths relative to the URDF, then under DIR."""
    name = ref.replace("\\", "/")
    if name.startswith("package://"):
        pkg, _, rest = name.removeprefix("package://").partition("/")
        out = []
        if mesh_dir is not None:
            out += [mesh_dir / pkg / rest, mesh_dir / rest, mesh_dir / Path(rest).name]
        out += [up / rest for up in (base_dir, *base_dir.parents) if up.name == pkg]
        out += [base_dir / pkg / rest, base_dir.parent / rest, base_dir / rest,
                base_dir / Path(rest).name]
        return out
    name = name.removeprefix("file://")
    out = [base_dir / name]
    if mesh_dir is not None:
        out += [mesh_dir / name, mesh_dir / Path(name).name]
    return out


def resolve_mesh(ref: str, *, base_dir: Path, mesh_dir: Path | None = None
                 ) -> tuple[Path | None, list[Path], bool]:
    """Find mesh ``ref`` (see ``mesh_candidates``): (the file or None, the places tried,
    whether it was taken with a name differing only in case)."""
    tried = mesh_candidates(ref, base_dir=base_dir, mesh_dir=mesh_dir)
    for cand in tried:
        if cand.is_file():
            return cand, tried, False
    for cand in tried:
        anchor = Path(cand.anchor) if cand.is_absolute() else Path(".")
        found, folded = _walk(anchor, list(cand.parts[1:] if cand.is_absolute() else cand.parts))
        if found is not None:
            log.info("mesh %s taken as %s (the case differs)", ref, found)
            return found, tried, folded
    return None, tried, False
