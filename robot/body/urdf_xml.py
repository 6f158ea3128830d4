"""A URDF file as plain records: its links (inertial, collision elements) and joints, each
number read and checked, with one-line errors naming the file and the element.

Xacro (a ``.xacro`` file, or xacro elements inside) is expanded with ROS's own xacro,
as published on PyPI by its maintainers (``xacro``, BSD; no ROS install needed), except
``$(find PKG)``, which needs ROS to find a package: that is refused in one line saying
to expand the file where ROS is (``xacro in.urdf.xacro > out.urdf``).
Visual elements are not read.
"""

from __future__ import annotations

import contextlib
import io
import logging
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robot.body.tree import Array, Inertial
from robot.errors import ConfigError

log = logging.getLogger(__name__)

XACRO_NS = "http://www.ros.org/wiki/xacro"
#: URDF joint types, and the ones the body tree takes (a hinge, or welded).
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
TAKEN_TYPES = ("revolute", "continuous", "fixed")


@dataclass(frozen=True)
class Origin:
    """An ``<origin>``: position [m] and rotation matrix (URDF's rpy: R = Rz(y) Ry(p) Rx(r))."""

    pos: Array
    rot: Array


@dataclass(frozen=True)
class Collision:
    """One ``<collision>``: its origin in the link frame, geometry kind ("box", "sphere",
    "cylinder", "capsule", "mesh") and its attributes as read (sizes [m], a mesh's
    filename and scale)."""

    origin: Origin
    kind: str
    size: tuple[float, ...] = ()
    filename: str = ""
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    name: str = ""


@dataclass(frozen=True)
class RawLink:
    name: str
    inertial: Inertial | None
    collisions: tuple[Collision, ...] = ()


@dataclass(frozen=True)
class RawJoint:
    """A ``<joint>``: axis in the child link frame (unit); limits as given (None: absent)."""

    name: str
    type: str
    parent: str
    child: str
    origin: Origin
    axis: tuple[float, float, float] = (1.0, 0.0, 0.0)
    lower: float | None = None
    upper: float | None = None
    effort: float | None = None
    velocity: float | None = None
    mimic: str = ""


@dataclass(frozen=True)
class RawUrdf:
    name: str
    links: dict[str, RawLink]
    joints: tuple[RawJoint, ...]
    warnings: tuple[str, ...] = field(default=())


def rpy_matrix(r: float, p: float, y: float) -> Array:
    cr, sr, cp, sp, cy, sy = (math.cos(r), math.sin(r), math.cos(p), math.sin(p),
                              math.cos(y), math.sin(y))
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


class _Reader:
    def __init__(self, path: Path) -> None:
        self.path = path

    def fail(self, where: str, what: str) -> ConfigError:
        return ConfigError(f"{self.path}: {where}: {what}")

    def numbers(self, el: ET.Element | None, attr: str, where: str, *, count: int,
                default: tuple[float, ...] | None = None) -> tuple[float, ...]:
        text = None if el is None else el.get(attr)
        if text is None:
            if default is None:
                tag = "element" if el is None else f"<{el.tag}>"
                raise self.fail(where, f"{tag} has no {attr}=")
            return default
        try:
            vals = tuple(float(v) for v in text.split())
        except ValueError:
            vals = ()
        if len(vals) != count or not all(math.isfinite(v) for v in vals):
            raise self.fail(where, f"{attr}=\"{text}\" is not {count} finite number(s)")
        return vals

    def origin(self, parent: ET.Element, where: str) -> Origin:
        el = parent.find("origin")
        xyz = self.numbers(el, "xyz", where, count=3, default=(0.0, 0.0, 0.0))
        rpy = self.numbers(el, "rpy", where, count=3, default=(0.0, 0.0, 0.0))
        return Origin(np.array(xyz), rpy_matrix(*rpy))

    def inertial(self, link: ET.Element, where: str) -> Inertial | None:
        el = link.find("inertial")
        if el is None:
            return None
        org = self.origin(el, where + " <inertial>")
        (mass,) = self.numbers(el.find("mass"), "value", where + " <mass>", count=1)
        inert = el.find("inertia")
        keys = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
        vals = [self.numbers(inert, k, where + " <inertia>", count=1, default=(0.0,))[0]
                for k in keys]
        ixx, iyy, izz, ixy, ixz, iyz = vals
        local = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        m = org.rot @ local @ org.rot.T
        return Inertial(mass=mass, com=(float(org.pos[0]), float(org.pos[1]), float(org.pos[2])),
                        inertia=(float(m[0, 0]), float(m[1, 1]), float(m[2, 2]),
                                 float(m[0, 1]), float(m[0, 2]), float(m[1, 2])))

    def collision(self, el: ET.Element, where: str) -> Collision:
        org = self.origin(el, where)
        geom = el.find("geometry")
        shape = None if geom is None else next(iter(geom), None)
        if shape is None:
            raise self.fail(where, "<collision> has no <geometry>")
        kind, name = shape.tag, el.get("name", "")
        if kind == "box":
            size = self.numbers(shape, "size", where, count=3)
            return Collision(org, kind, tuple(s / 2.0 for s in size), name=name)
        if kind == "sphere":
            return Collision(org, kind, self.numbers(shape, "radius", where, count=1), name=name)
        if kind in ("cylinder", "capsule"):
            (r,) = self.numbers(shape, "radius", where, count=1)
            (length,) = self.numbers(shape, "length", where, count=1)
            return Collision(org, kind, (r, length / 2.0), name=name)
        if kind == "mesh":
            ref = shape.get("filename")
            if not ref:
                raise self.fail(where, "<mesh> has no filename=")
            scale = self.numbers(shape, "scale", where, count=3, default=(1.0, 1.0, 1.0))
            return Collision(org, kind, filename=ref, scale=(scale[0], scale[1], scale[2]),
                             name=name)
        raise self.fail(where, f"collision geometry <{kind}> is not one of box, sphere, "
                               "cylinder, capsule, mesh")

    def joint(self, el: ET.Element) -> RawJoint:
        name = el.get("name", "")
        where = f"joint {name!r}"
        kind = el.get("type", "")
        if kind not in JOINT_TYPES:
            raise self.fail(where, f"type \"{kind}\" is not a URDF joint type ({', '.join(JOINT_TYPES)})")
        ends = []
        for tag in ("parent", "child"):
            sub = el.find(tag)
            if sub is None or not sub.get("link"):
                raise self.fail(where, f"has no <{tag} link=\"...\"/>")
            ends.append(sub.get("link", ""))
        axis = np.array(self.numbers(el.find("axis"), "xyz", where + " <axis>", count=3,
                                     default=(1.0, 0.0, 0.0)))
        norm = float(np.linalg.norm(axis))
        if kind in ("revolute", "continuous") and norm < 1e-12:
            raise self.fail(where, "<axis xyz=\"0 0 0\"> has no direction")
        unit = axis / norm if norm > 0 else np.array([1.0, 0.0, 0.0])
        lim = el.find("limit")
        got = {k: (None if lim is None or lim.get(k) is None
                   else self.numbers(lim, k, where + " <limit>", count=1)[0])
               for k in ("lower", "upper", "effort", "velocity")}
        mimic = el.find("mimic")
        return RawJoint(name=name, type=kind, parent=ends[0], child=ends[1],
                        origin=self.origin(el, where), axis=(float(unit[0]), float(unit[1]),
                                                             float(unit[2])),
                        lower=got["lower"], upper=got["upper"], effort=got["effort"],
                        velocity=got["velocity"],
                        mimic="" if mimic is None else mimic.get("joint", "?"))


def _expand_xacro(path: Path) -> tuple[str, list[str]]:
    import xacro  # ROS's xacro from PyPI

    said = io.StringIO()
    try:
        with contextlib.redirect_stderr(said):
            doc = xacro.process_file(str(path))
    except xacro.XacroException as err:
        text = " ".join(str(err).split())
        if "ament_index_python" in text or "substitution args" in text:
            raise ConfigError(f"{path}: xacro's $(find PKG) needs ROS to find the package: "
                              f"expand it where ROS is (xacro {path.name} > robot.urdf) and "
                              f"import robot.urdf") from err
        raise ConfigError(f"{path}: xacro cannot expand it: {text}") from err
    notes = [f"{path.name}: xacro: {line.strip()}" for line in said.getvalue().splitlines()
             if line.strip().startswith("warning")]
    return doc.toxml(), notes


def read_raw(path: Path) -> RawUrdf:
    """The links and joints of the URDF (or xacro) at ``path``."""
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as err:
        raise ConfigError(f"{path}: cannot read the URDF: {err.strerror}") from err
    notes: list[str] = []
    if path.suffix == ".xacro" or XACRO_NS in text or "<xacro:" in text:
        text, notes = _expand_xacro(path)
    try:
        root = ET.fromstring(text)
    except ET.ParseError as err:
        raise ConfigError(f"{path}: not well-formed XML: {err}") from err
    if root.tag != "robot":
        raise ConfigError(f"{path}: not a URDF: the root element is <{root.tag}>, not <robot>")
    rd = _Reader(path)
    links: dict[str, RawLink] = {}
    for el in root.findall("link"):
        name = el.get("name", "")
        where = f"link {name!r}"
        if not name or name in links:
            raise rd.fail(where, "a link needs a name of its own" if not name else "defined twice")
        cols = tuple(rd.collision(c, f"{where} <collision> {i}")
                     for i, c in enumerate(el.findall("collision")))
        links[name] = RawLink(name, rd.inertial(el, where), cols)
    joints = tuple(rd.joint(el) for el in root.findall("joint"))
    if not links:
        raise ConfigError(f"{path}: the URDF has no <link>")
    return RawUrdf(root.get("name", path.stem), links, joints, tuple(notes))
