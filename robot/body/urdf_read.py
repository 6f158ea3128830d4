"""A builder's URDF as the project's body description (robot/body/tree.py).

Takes what exporters write (onshape-to-robot, fusion2urdf, the SolidWorks exporter, ROS
description packages): an empty root link, odd rpy origins, package:// mesh paths,
effort/velocity limits, continuous joints. Links joined by a fixed joint are fused into
their parent (mass, centre of mass and inertia by the parallel axis theorem; collision
shapes moved) and kept as a Frame of their name (exporters put soles and IMUs there as
massless links). A collision mesh becomes its convex hull (robot/body/meshes.py); visual
elements are ignored. A mimic joint is taken as an independent hinge, with a warning.
Prismatic, planar and floating joints, several roots, loops: refused in one line naming
the joint or links. Physical checks (robot/body/checks.py) run last.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robot.body import inertia, meshes
from robot.body.checks import check_tree
from robot.body.tree import (
    Array,
    BodyTree,
    Frame,
    Hinge,
    Inertial,
    Link,
    Shape,
    equivalent_box,
    matrix_to_quat,
)
from robot.body.urdf_xml import TAKEN_TYPES, Collision, RawJoint, RawLink, RawUrdf, read_raw
from robot.errors import ConfigError

MISSING_MESH = ("error", "box")


def _vec(a: Array) -> tuple[float, float, float]:
    return (float(a[0]), float(a[1]), float(a[2]))


@dataclass
class _Body:
    """A link of the tree being built, with what fused links brought to it."""

    name: str
    parent: int
    pos: Array
    rot: Array
    joint: Hinge | None
    inertial: Inertial | None = None
    shapes: list[Shape] = field(default_factory=list)
    frames: list[Frame] = field(default_factory=list)


class _Builder:
    def __init__(self, path: Path, raw: RawUrdf, *, mesh_dir: Path | None,
                 missing_mesh: str, max_vertices: int) -> None:
        self.path, self.raw = path, raw
        self.mesh_dir, self.missing_mesh, self.max_vertices = mesh_dir, missing_mesh, max_vertices
        self.warnings: list[str] = list(raw.warnings)
        self.bodies: list[_Body] = []
        self.hulls: dict[tuple[Path, tuple[float, float, float]], meshes.Hull] = {}
        self.boxed: set[str] = set()
        self.folded: set[Path] = set()

    def fail(self, what: str) -> ConfigError:
        return ConfigError(f"{self.path}: {what}")

    def root(self) -> str:
        children: dict[str, str] = {}
        names = [j.name for j in self.raw.joints]
        for j in self.raw.joints:
            if not j.name or names.count(j.name) > 1:
                raise self.fail(f"joint {j.name!r}: a joint needs a name of its own"
                                if not j.name else f"joint {j.name!r}: defined twice")
            for end in (j.parent, j.child):
                if end not in self.raw.links:
                    raise self.fail(f"joint {j.name!r}: link {end!r} is not defined")
            if j.child in children:
                raise self.fail(f"joint {j.name!r}: link {j.child!r} already hangs from joint "
                                f"{children[j.child]!r} (a loop: URDF is a tree)")
            children[j.child] = j.name
        roots = [n for n in self.raw.links if n not in children]
        if len(roots) != 1:
            what = ", ".join(repr(r) for r in roots) if roots else "none (every link has a parent: a loop)"
            raise self.fail(f"a URDF needs exactly one root link, found {what}")
        return roots[0]

    def build(self) -> BodyTree:
        root = self.root()
        self.bodies.append(_Body(root, -1, np.zeros(3), np.eye(3), None))
        self.take(self.raw.links[root], 0, np.zeros(3), np.eye(3))
        reached = {b.name for b in self.bodies} | {f.name for b in self.bodies for f in b.frames}
        lost = [n for n in self.raw.links if n not in reached]
        if lost:
            raise self.fail(f"links {', '.join(map(repr, lost))} are not reached from the root "
                            f"{root!r} (a loop)")
        links = tuple(Link(name=b.name, parent=b.parent, pos=_vec(b.pos),
                           quat=matrix_to_quat(b.rot), inertial=b.inertial, joint=b.joint,
                           shapes=tuple(b.shapes), frames=tuple(b.frames)) for b in self.bodies)
        return BodyTree(links=links, source=str(self.path))

    def take(self, link: RawLink, owner: int, pos: Array, rot: Array) -> None:
        """Add ``link`` (placed at ``pos``, ``rot`` in body ``owner``'s frame) to that body,
        then its children: a hinge starts a body, a fixed joint fuses into this one."""
        body = self.bodies[owner]
        if link.inertial is not None:
            body.inertial = inertia.combined(body.inertial, inertia.transformed(link.inertial, pos, rot))
        for k, col in enumerate(link.collisions):
            shape = self.shape(link, k, col, pos, rot)
            if shape is not None:
                body.shapes.append(shape)
        for j in self.raw.joints:
            if j.parent != link.name:
                continue
            if j.type not in TAKEN_TYPES:
                raise self.fail(f"joint {j.name!r}: a {j.type} joint (between {j.parent!r} and "
                                f"{j.child!r}) is not taken: the body takes revolute, "
                                "continuous and fixed joints")
            child = self.raw.links[j.child]
            cpos, crot = pos + rot @ j.origin.pos, rot @ j.origin.rot
            if j.type == "fixed":
                body.frames.append(Frame(child.name, _vec(cpos), matrix_to_quat(crot)))
                self.take(child, owner, cpos, crot)
                continue
            self.bodies.append(_Body(child.name, owner, cpos, crot, self.hinge(j)))
            self.take(child, len(self.bodies) - 1, np.zeros(3), np.eye(3))

    def hinge(self, j: RawJoint) -> Hinge:
        where = f"joint {j.name!r}"
        if j.mimic:
            self.warnings.append(f"{where} mimics joint {j.mimic!r}: taken as an independent "
                                 "hinge (the simulation drives it on its own)")
        rng: tuple[float, float] | None = None
        if j.type == "revolute":
            if j.lower is None or j.upper is None:
                self.warnings.append(f"{where}: a revolute joint without lower/upper limits: "
                                     "taken without a range")
            elif j.lower > j.upper:
                raise self.fail(f"{where}: <limit lower=\"{j.lower}\" upper=\"{j.upper}\">: lower "
                                "is above upper")
            elif j.lower == j.upper:
                self.warnings.append(f"{where}: <limit lower=upper={j.lower}>: taken as no range "
                                     "(exporters write that for a joint without limits)")
            else:
                rng = (j.lower, j.upper)
        effort = j.effort if j.effort is not None and j.effort > 0 else None
        velocity = j.velocity if j.velocity is not None and j.velocity > 0 else None
        return Hinge(name=j.name, axis=j.axis, range=rng, effort=effort, velocity=velocity)

    def shape(self, link: RawLink, k: int, col: Collision, pos: Array, rot: Array) -> Shape | None:
        spos, srot = pos + rot @ col.origin.pos, rot @ col.origin.rot
        name = col.name or (f"{link.name}_{k}" if len(link.collisions) > 1 else link.name)
        if col.kind != "mesh":
            return Shape(kind=col.kind, pos=_vec(spos), quat=matrix_to_quat(srot),
                         size=col.size, name=name)
        found, tried, folded = meshes.resolve_mesh(col.filename, base_dir=self.path.parent,
                                                   mesh_dir=self.mesh_dir)
        where = f"link {link.name!r}: collision mesh {col.filename!r}"
        if found is None:
            return self.stand_in(link, where, tried, pos, rot)
        if folded and found not in self.folded:
            self.folded.add(found)
            self.warnings.append(f"{where}: taken as {found} (its name differs in case)")
        key = (found, col.scale)
        if key not in self.hulls:
            try:
                self.hulls[key] = meshes.hull(found, scale=col.scale, max_vertices=self.max_vertices)
            except ConfigError as err:
                raise self.fail(f"{where}: {err}") from err
        hull = self.hulls[key]
        return Shape(kind="hull", pos=_vec(spos), quat=matrix_to_quat(srot),
                     vertices=hull.vertices, name=name, note=hull.note(found.name))

    def stand_in(self, link: RawLink, where: str, tried: list[Path], pos: Array,
                 rot: Array) -> Shape | None:
        looked = ", ".join(str(p) for p in tried[:4]) + (" ..." if len(tried) > 4 else "")
        if self.missing_mesh != "box":
            raise self.fail(f"{where} not found (looked at {looked}); give the folder that holds "
                            "it (--mesh-dir), or --missing-meshes box for the link's "
                            "equivalent-inertia box")
        if link.name in self.boxed:
            return None
        self.boxed.add(link.name)
        if link.inertial is None or not link.inertial.mass > 0:
            raise self.fail(f"{where} not found, and the link has no mass to size an "
                            "equivalent-inertia box for it")
        box = equivalent_box(inertia.transformed(link.inertial, pos, rot),
                                     name=f"{link.name}_inertia_box",
                                     note=f"stand-in: {where} not found; the link's "
                                          "equivalent-inertia box")
        self.warnings.append(f"{where} not found: replaced by the link's equivalent-inertia box "
                             f"({' x '.join(f'{2000 * s:.1f}' for s in box.size)} mm)")
        return box


def read_urdf(path: Path | str, *, mesh_dir: Path | str | None = None,
              missing_mesh: str = "error", fix_inertia: bool = False,
              max_vertices: int = meshes.DEFAULT_MAX_VERTICES) -> tuple[BodyTree, list[str]]:
    """The body tree of the URDF (or xacro) at ``path`` and the warnings met on the way.

    mesh_dir: where package:// meshes are (see robot.body.meshes.mesh_candidates);
    missing_mesh: "error" (a missing collision mesh is refused) or "box" (replaced by the
    link's equivalent-inertia box, with a warning); fix_inertia: fix what
    robot.body.checks finds instead of refusing it; max_vertices: per collision hull.
    Raises ConfigError (one line naming the file and the link, joint or mesh)."""
    if missing_mesh not in MISSING_MESH:
        raise ConfigError(f"missing_mesh: {missing_mesh!r} is not one of {', '.join(MISSING_MESH)}")
    file = Path(path)
    if not file.is_file():
        raise ConfigError(f"{file}: no such URDF file")
    builder = _Builder(file, read_raw(file), mesh_dir=None if mesh_dir is None else Path(mesh_dir),
                       missing_mesh=missing_mesh, max_vertices=max_vertices)
    tree = builder.build()
    tree, found = check_tree(tree, fix=fix_inertia)
    return tree, builder.warnings + found
