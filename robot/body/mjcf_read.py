"""An MJCF file (MuJoCo's XML: a Menagerie model, onshape-to-robot's ``robot.xml``) → the
body description (robot/body/tree.py), in the model's own terms.

MuJoCo itself reads the file: its compiler is the format's definition (default classes,
childclass, includes, angle units, euler sequences, fromto, inertia from geoms), so what
comes out is what MuJoCo would simulate. Before compiling, every mesh file is looked up
(a name differing only in case from the file on disk is taken, with a warning) and given
to MuJoCo under a name of its own; a mesh whose file is missing gets a tiny stand-in so the
file still compiles, and afterwards:

- a missing mesh that only a visual geom uses (contype and conaffinity 0: MuJoCo's
  meaning) is dropped silently: visual meshes are never needed;
- a missing mesh a colliding geom uses is one line naming the mesh, file and body, or,
  with ``missing_mesh="box"``, that geom becomes the body's equivalent-inertia box (a
  warning names it).

A colliding mesh geom becomes its convex hull (what MuJoCo collides anyway), with at
most ``max_hull`` vertices (MuJoCo's ``maxhullvert``). Textures, height fields and skins
are dropped (drawing only). The robot is the world's child with a free joint (or its only
child body); other world geoms (a floor in a scene file) are not part of it.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import mujoco
import numpy as np

from robot.body.checks import check_tree
from robot.body.mjcf_files import prepare
from robot.body.tree import BodyTree, Frame, Hinge, Inertial, Link, Shape, equivalent_box, quat_to_matrix
from robot.errors import ConfigError

#: Hull vertices kept per mesh (MuJoCo's ``maxhullvert``), as robot/body/meshes.py keeps
#: for a URDF's meshes: on the Open Duck Mini's 17 STLs the dropped hull vertices lie at
#: most 1.1 mm outside the kept hull (median 0.2 mm).
MAX_HULL = 64
GEOM_KINDS = {int(mujoco.mjtGeom.mjGEOM_BOX): "box", int(mujoco.mjtGeom.mjGEOM_SPHERE): "sphere",
              int(mujoco.mjtGeom.mjGEOM_CAPSULE): "capsule",
              int(mujoco.mjtGeom.mjGEOM_CYLINDER): "cylinder"}
_MESH = int(mujoco.mjtGeom.mjGEOM_MESH)


def _robot_root(model: mujoco.MjModel, path: Path) -> int:
    tops = [b for b in range(1, model.nbody) if model.body_parentid[b] == 0]
    free = [b for b in tops if model.body_jntnum[b] >= 1 and model.jnt_type[model.body_jntadr[b]]
            == mujoco.mjtJoint.mjJNT_FREE]
    if len(free) == 1:
        return free[0]
    moving = [b for b in tops if model.body_subtreemass[b] > 0]
    if len(free) == 0 and len(moving) == 1:
        return moving[0]
    names = ", ".join(model.body(b).name or f"#{b}" for b in (free or moving))
    raise ConfigError(f"{path}: cannot tell which body is the robot: the world holds "
                      f"{len(free or moving)} candidates ({names}); expected one body with a "
                      "free joint")


def _inertial(model: mujoco.MjModel, b: int) -> Inertial | None:
    mass = float(model.body_mass[b])
    if mass <= 0.0:
        return None
    r = quat_to_matrix(model.body_iquat[b])
    full = r @ np.diag(model.body_inertia[b]) @ r.T
    return Inertial(mass, tuple(float(v) for v in model.body_ipos[b]),  # type: ignore[arg-type]
                    (float(full[0, 0]), float(full[1, 1]), float(full[2, 2]),
                     float(full[0, 1]), float(full[0, 2]), float(full[1, 2])))


def _hinge(model: mujoco.MjModel, b: int, path: Path) -> Hinge | None:
    name = model.body(b).name
    count = int(model.body_jntnum[b])
    if count == 0:
        return None
    if count > 1:
        raise ConfigError(f"{path}: body {name!r}: {count} joints on one body; expected one "
                          "hinge per body")
    j = int(model.body_jntadr[b])
    jname = model.joint(j).name or f"joint of {name}"
    if model.jnt_type[j] != mujoco.mjtJoint.mjJNT_HINGE:
        kind = {int(mujoco.mjtJoint.mjJNT_SLIDE): "slide", int(mujoco.mjtJoint.mjJNT_BALL): "ball",
                int(mujoco.mjtJoint.mjJNT_FREE): "free"}[int(model.jnt_type[j])]
        raise ConfigError(f"{path}: joint {jname!r} on body {name!r}: a {kind} joint; servos "
                          "drive hinges only")
    if model.qpos0[model.jnt_qposadr[j]] != 0.0:
        raise ConfigError(f"{path}: joint {jname!r}: ref {model.qpos0[model.jnt_qposadr[j]]:g} "
                          "rad; a hinge whose reference angle is not 0 is not supported "
                          "(set ref to 0 and turn the body instead)")
    limited = bool(model.jnt_limited[j])
    effort = float(model.jnt_actfrcrange[j][1]) if model.jnt_actfrclimited[j] else None
    for a in range(model.nu):   # a position actuator's force range is the servo's effort
        if model.actuator_trnid[a][0] == j and model.actuator_forcelimited[a] and effort is None:
            effort = float(model.actuator_forcerange[a][1])
    return Hinge(jname, tuple(float(v) for v in model.jnt_axis[j]),  # type: ignore[arg-type]
                 tuple(float(v) for v in model.jnt_pos[j]),  # type: ignore[arg-type]
                 (float(model.jnt_range[j][0]), float(model.jnt_range[j][1])) if limited else None,
                 effort)


def hull_of(model: mujoco.MjModel, mesh: int) -> tuple[tuple[float, float, float], ...]:
    """The convex hull's vertices of compiled mesh ``mesh`` in its (centred) frame [m]."""
    graph, adr = model.mesh_graph, int(model.mesh_graphadr[mesh])
    start, count = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
    verts = model.mesh_vert[start:start + count]
    if adr < 0:
        pts = verts
    else:
        n = int(graph[adr])
        pts = verts[graph[adr + 2 + n: adr + 2 + 2 * n]]
    return tuple((float(x), float(y), float(z)) for x, y, z in pts)


def read_mjcf(path: str | Path, *, missing_mesh: str = "error", max_hull: int = MAX_HULL,
              fix_inertia: bool = False) -> tuple[BodyTree, list[str]]:
    """The robot in MJCF file ``path`` and the warnings (see the module docstring); the
    tree passes robot/body/checks.py (``fix_inertia``: fixed where it can be, with a
    warning)."""
    p = Path(path)
    warnings: list[str] = []
    xml, assets, missing = prepare(p, max_hull, warnings)
    try:
        model = mujoco.MjModel.from_xml_string(xml, assets)
    except ValueError as e:
        first = str(e).strip().splitlines()[0] if str(e).strip() else "unknown error"
        raise ConfigError(f"{p}: MuJoCo cannot compile the model: {first}") from e
    root = _robot_root(model, p)
    order = [root] + [b for b in range(root + 1, model.nbody) if _under(model, b, root)]
    index = {b: i for i, b in enumerate(order)}
    links: list[Link] = []
    for b in order:
        name = model.body(b).name or f"body{b}"
        shapes: list[Shape] = []
        for g in range(int(model.body_geomadr[b]), int(model.body_geomadr[b] + model.body_geomnum[b])):
            shape = _shape(model, g, b, missing, missing_mesh, p, warnings)
            if shape is not None:
                shapes.append(shape)
        inertial = _inertial(model, b)
        if any(s.kind == "inertia_box" for s in shapes):
            notes = "; ".join(s.note for s in shapes if s.kind == "inertia_box")
            shapes = [s for s in shapes if s.kind != "inertia_box"]
            if inertial is None:
                raise ConfigError(f"{p}: body {model.body(b).name!r}: a collision mesh is "
                                  "missing and the body has no mass to size a stand-in box")
            shapes.append(equivalent_box(inertial, note=notes))
            warnings.append(f"{p}: body {name!r}: collision mesh{'es' if notes.count(';') else ''} "
                            f"missing ({notes.replace('stand-in for missing mesh ', '')}): the "
                            "body's equivalent-inertia box instead")
        frames = tuple(Frame(model.site(s).name, tuple(map(float, model.site_pos[s])),  # type: ignore[arg-type]
                             tuple(map(float, model.site_quat[s])))  # type: ignore[arg-type]
                       for s in range(model.nsite) if model.site_bodyid[s] == b and model.site(s).name)
        links.append(Link(name, -1 if b == root else index[int(model.body_parentid[b])],
                          (0.0, 0.0, 0.0) if b == root else tuple(map(float, model.body_pos[b])),  # type: ignore[arg-type]
                          (1.0, 0.0, 0.0, 0.0) if b == root else tuple(map(float, model.body_quat[b])),  # type: ignore[arg-type]
                          inertial, None if b == root else _hinge(model, b, p),
                          tuple(shapes), frames))
    excludes = []
    for sig in model.exclude_signature:
        b1, b2 = int(sig) >> 16, int(sig) & 0xFFFF
        if b1 in index and b2 in index:
            excludes.append((links[index[b1]].name, links[index[b2]].name))
    tree, fixed = check_tree(_frames_kept(BodyTree(tuple(links), source=str(p),
                                                   excludes=tuple(excludes))), fix=fix_inertia)
    return tree, warnings + fixed


#: A welded body lighter than this, with no shapes and no children, is a marker: an
#: exporter's frame (onshape-to-robot writes its frames as 1e-9 kg bodies) [kg].
MARKER_MASS = 1e-6


def _frames_kept(tree: BodyTree) -> BodyTree:
    """``tree`` with every marker body (MARKER_MASS) turned into a Frame of its name on its
    parent."""
    parents = {link.parent for link in tree.links}
    marker = {i for i, link in enumerate(tree.links)
              if i > 0 and link.joint is None and not link.shapes and i not in parents
              and (link.inertial is None or link.inertial.mass < MARKER_MASS)}
    if not marker:
        return tree
    extra: dict[int, list[Frame]] = {}
    for i in marker:
        link = tree.links[i]
        extra.setdefault(link.parent, []).append(Frame(link.name, link.pos, link.quat))
    new_index: dict[int, int] = {}
    links: list[Link] = []
    for i, link in enumerate(tree.links):
        if i in marker:
            continue
        new_index[i] = len(links)
        links.append(dataclasses.replace(
            link, parent=new_index[link.parent] if link.parent >= 0 else -1,
            frames=(*link.frames, *extra.get(i, ()))))
    names = {link.name for link in links}
    excludes = tuple(pair for pair in tree.excludes if set(pair) <= names)
    return BodyTree(tuple(links), source=tree.source, excludes=excludes)


def _under(model: mujoco.MjModel, b: int, root: int) -> bool:
    while b > 0:
        if b == root:
            return True
        b = int(model.body_parentid[b])
    return False


def _shape(model: mujoco.MjModel, g: int, b: int, missing: dict[str, tuple[str, str]],
           missing_mesh: str, path: Path, warnings: list[str]) -> Shape | None:
    """Geom ``g`` as a collision Shape (None: a visual geom)."""
    if not (model.geom_contype[g] or model.geom_conaffinity[g]):
        return None
    kind = int(model.geom_type[g])
    pos = tuple(float(v) for v in model.geom_pos[g])
    quat = tuple(float(v) for v in model.geom_quat[g])
    gname = model.geom(g).name
    bname = model.body(b).name
    if kind in GEOM_KINDS:
        size = {"box": 3, "sphere": 1, "capsule": 2, "cylinder": 2}[GEOM_KINDS[kind]]
        return Shape(GEOM_KINDS[kind], pos, quat,  # type: ignore[arg-type]
                     tuple(float(v) for v in model.geom_size[g][:size]), name=gname)
    if kind != _MESH:
        raise ConfigError(f"{path}: geom {gname or '#' + str(g)} on body {bname!r}: a "
                          f"{mujoco.mjtGeom(kind).name[7:].lower()} collides; a robot's collision "
                          "shapes must be boxes, spheres, capsules, cylinders or meshes")
    mesh = int(model.geom_dataid[g])
    mname = model.mesh(mesh).name
    if mname in missing:
        ref, _ = missing[mname]
        if missing_mesh != "box":
            raise ConfigError(f"{path}: body {bname!r}: collision mesh {mname!r} (file {ref!r}) "
                              "is missing; put the file where the model says, or import with "
                              "--missing-meshes box to use the body's equivalent-inertia box")
        return Shape("inertia_box", name=gname, note=f"stand-in for missing mesh {ref}")
    verts = hull_of(model, mesh)
    return Shape("hull", pos, quat, vertices=verts, name=gname,  # type: ignore[arg-type]
                 note=f"mesh {mname}: convex hull, {len(verts)} vertices")
