"""Physical checks of a body tree, shared by the URDF and MJCF readers.

Refused (one line naming the link and what was found), or with ``fix`` fixed with a
warning saying what became what:

- a mass or centre of mass that is negative or not finite, and a moving link (one with a
  hinge, or the root: the base floats) whose subtree has no mass. Fix: the mass, centre
  of mass and inertia of the link's collision shapes at 1000 kg/m^3 (MuJoCo's default
  density, as its ``inertiafromgeom`` would give); a link without shapes stays refused.
- an inertia that is not positive definite, or whose principal moments break the
  triangle inequality (a + b >= c: no rigid body has it otherwise). Fix: the three moments
  set to their mean, axes kept (MuJoCo's ``balanceinertia`` rule); a mean <= 0: a solid
  sphere of the link's mass at 1000 kg/m^3.
- an inertia wrong by orders of magnitude: the density of the link's equivalent-inertia
  box outside DENSITY_RANGE. Fix: the moments scaled (mass, axes and ratios kept) until
  the density is at the nearest end of the range.
"""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np

from robot.body import inertia
from robot.body.tree import BodyTree, Inertial, Link, quat_to_matrix
from robot.errors import ConfigError

#: Plausible density of a link's equivalent-inertia box [kg/m^3]. The published kits'
#: links lie between 150 (a hollow printed head) and 1550 (a servo and its bracket); a
#: large thin-walled shell comes to about 70, tungsten, the densest thing a robot holds,
#: to 19300. A unit slip moves it far out: an inertia 1000x off (g m^2, kg mm^2 / 1000)
#: moves the density 1000^1.5 = 31623x, a mass in grams read as kg 1000^2.5x.
DENSITY_RANGE = (20.0, 20000.0)
#: MuJoCo's default geom density, for masses made from collision shapes [kg/m^3].
SHAPE_DENSITY = 1000.0

_GEOMS = {"box": mujoco.mjtGeom.mjGEOM_BOX, "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
          "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE, "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
          "hull": mujoco.mjtGeom.mjGEOM_MESH}


def _fmt(values: tuple[float, ...] | np.ndarray) -> str:
    return "(" + ", ".join(f"{float(v):.4g}" for v in values) + ")"


def shapes_inertial(link: Link, *, density: float = SHAPE_DENSITY) -> Inertial | None:
    """Mass, centre of mass and inertia of ``link``'s collision shapes, uniformly of
    ``density`` [kg/m^3], as MuJoCo computes them; None without collision shapes."""
    shapes = [s for s in link.shapes if not s.visual]
    if not shapes:
        return None
    spec = mujoco.MjSpec()
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE
    body = spec.worldbody.add_body(name="b")
    for k, s in enumerate(shapes):
        geom = body.add_geom(type=_GEOMS[s.kind], pos=list(s.pos), quat=list(s.quat),
                             density=density)
        if s.kind == "hull":
            spec.add_mesh(name=f"m{k}", uservert=np.ravel(s.vertices).tolist())
            geom.meshname = f"m{k}"
        else:
            geom.size = (list(s.size) + [0.0, 0.0, 0.0])[:3]
    model = spec.compile()
    r = quat_to_matrix(model.body_iquat[1])
    return inertia.from_matrix(float(model.body_mass[1]), model.body_ipos[1],
                               r @ np.diag(model.body_inertia[1]) @ r.T)


class _Checker:
    def __init__(self, tree: BodyTree, fix: bool) -> None:
        self.tree, self.fix = tree, fix
        self.inertials = [link.inertial for link in tree.links]
        self.warnings: list[str] = []

    def where(self, i: int) -> str:
        return f"{self.tree.source}: link {self.tree.links[i].name!r}"

    def refuse_or_fix(self, i: int, found: str, *, need: str = "") -> bool:
        """Refuse ``found`` unless fixing; True when the caller should fix it."""
        if not self.fix:
            raise ConfigError(f"{self.where(i)}: {found}{need}")
        return True

    def from_shapes(self, i: int, found: str) -> None:
        self.refuse_or_fix(i, found, need="; give it a mass and inertia, or import with "
                           "--fix-inertia (made from its collision shapes)")
        new = shapes_inertial(self.tree.links[i])
        if new is None or not new.mass > 0:
            raise ConfigError(f"{self.where(i)}: {found}, and it has no collision shape to "
                              "make a mass from")
        old = self.inertials[i]
        self.inertials[i] = new
        was = "none" if old is None else f"{old.mass:.4g} kg"
        self.warnings.append(f"{self.where(i)}: {found}: mass {was} -> {new.mass:.4g} kg, "
                             f"centre of mass {_fmt(new.com)} m, inertia {_fmt(new.inertia)} "
                             f"kg m^2 from its collision shapes at {SHAPE_DENSITY:g} kg/m^3")

    def masses(self) -> None:
        for i, inert in enumerate(self.inertials):
            if inert is None:
                continue
            if not math.isfinite(inert.mass) or inert.mass < 0:
                self.from_shapes(i, f"mass {inert.mass} kg")
            elif not all(math.isfinite(c) for c in inert.com):
                self.from_shapes(i, f"centre of mass {inert.com} is not finite")

    def subtree_mass(self, i: int) -> float:
        own = self.inertials[i]
        return (own.mass if own else 0.0) + sum(self.subtree_mass(k) for k in self.tree.children(i))

    def moving(self) -> None:
        for i in reversed(range(len(self.tree.links))):
            link = self.tree.links[i]
            if (link.joint is not None or link.parent < 0) and not self.subtree_mass(i) > 0:
                kind = f"moved by hinge {link.joint.name!r}" if link.joint else "the root"
                self.from_shapes(i, f"{kind}, it and the links it carries have no mass")

    def moments(self, i: int) -> None:
        inert = self.inertials[i]
        if inert is None or not inert.mass > 0:
            return
        if not all(math.isfinite(v) for v in inert.inertia):
            found = f"inertia {_fmt(inert.inertia)} kg m^2 is not finite"
            self.refuse_or_fix(i, found, need="; --fix-inertia puts a sphere's")
            self.replace_moments(i, inert, np.full(3, math.nan), np.eye(3), found)
            return
        moments, axes = inertia.principal(inert)
        a, b, c = moments
        if not a > 0:
            found = f"inertia not positive definite (principal moments {_fmt(moments)} kg m^2)"
        elif a + b < c * (1.0 - 1e-12):
            found = (f"principal moments {_fmt(moments)} kg m^2 break the triangle inequality "
                     f"({a:.4g} + {b:.4g} < {c:.4g}: no rigid body has them)")
        else:
            return
        self.refuse_or_fix(i, found, need="; --fix-inertia sets the moments to their mean")
        self.replace_moments(i, inert, moments, axes, found)

    def replace_moments(self, i: int, inert: Inertial, moments: np.ndarray, axes: np.ndarray,
                        found: str) -> None:
        mean = float(np.mean(moments))
        if math.isfinite(mean) and mean > 0:
            new_m = axes @ np.diag([mean] * 3) @ axes.T
            how = "each set to their mean (MuJoCo's balanceinertia)"
        else:
            sphere = inertia.sphere_inertial(inert.mass, inert.com, density=SHAPE_DENSITY)
            new_m, how = sphere.matrix(), f"a solid sphere's of its mass at {SHAPE_DENSITY:g} kg/m^3"
        self.inertials[i] = inertia.from_matrix(inert.mass, inert.com, new_m)
        self.warnings.append(f"{self.where(i)}: {found}: moments -> {_fmt(np.linalg.eigvalsh(new_m))} "
                             f"kg m^2, {how}")

    def density(self, i: int) -> None:
        inert = self.inertials[i]
        if inert is None or not inert.mass > 0:
            return
        rho = inertia.box_density(inert)
        low, high = DENSITY_RANGE
        if low <= rho <= high:
            return
        target = low if rho < low else high
        found = (f"mass {inert.mass:.4g} kg with inertia {_fmt(inert.inertia)} kg m^2: its "
                 f"equivalent-inertia box has a density of {rho:.3g} kg/m^3, outside the "
                 f"plausible {low:g}-{high:g} (an inertia or mass in the wrong unit?)")
        self.refuse_or_fix(i, found, need="; --fix-inertia scales the inertia into the range")
        if not math.isfinite(rho):
            raise ConfigError(f"{self.where(i)}: {found}; a flat box cannot be scaled")
        scale = (rho / target) ** (2.0 / 3.0)
        new = inertia.from_matrix(inert.mass, inert.com, inert.matrix() * scale)
        self.inertials[i] = new
        self.warnings.append(f"{self.where(i)}: {found}: inertia scaled by {scale:.4g} to "
                             f"{_fmt(new.inertia)} kg m^2 (density {target:g} kg/m^3)")


def check_tree(tree: BodyTree, *, fix: bool = False) -> tuple[BodyTree, list[str]]:
    """``tree`` checked (see the module docstring): the tree (fixed where ``fix``) and the
    warnings of every fix. Raises ConfigError naming the link and what was found."""
    ck = _Checker(tree, fix)
    ck.masses()
    ck.moving()
    for i in range(len(tree.links)):
        ck.moments(i)
        ck.density(i)
    links = tuple(link if ck.inertials[i] is link.inertial else
                  dataclasses.replace(link, inertial=ck.inertials[i])
                  for i, link in enumerate(tree.links))
    return dataclasses.replace(tree, links=links), ck.warnings

