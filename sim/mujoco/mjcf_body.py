"""A body tree in the robot's terms (robot/config/body_tree.py: the box model or an
imported body) as the MJCF ``worldbody`` the simulation runs: one writer for every robot.

- The root link is the ``torso`` body with the free joint ``root``; its frame is the
  pelvis frame, so every sim feature that reads the torso (odometry, heading, the IMU,
  pushes) sees the same frame on every robot.
- Each hinge is a joint named as the tree names it (the project's joint names), with its
  axis, anchor, range and ``ref``; the servo law (sim/mujoco/mjcf_robot.py) is added to
  it and to its actuator.
- Each link's inertial as it is: ``diaginertia`` where the tensor has no products (MuJoCo
  keeps the axes as given), else ``fullinertia``.
- Shapes: a visual one is drawn only (class ``visual``); a collision one is in its contact
  class: legs collide with the floor and the other leg, the rest with the floor only
  (mjcf_robot.py's CONTACT). A leg is every link from the first hip joint out; a foot
  every link from the last ankle joint out, and its collision shapes are ``r_foot``,
  ``r_foot_1``... (sim/mujoco/geoms.py). A hull is a mesh given by its vertices (MuJoCo
  collides a mesh by its hull). A body without visual shapes (an imported one) is drawn
  by its collision shapes, each in its place's material.
- Frames become sites (``imu``, ``r_sole``, ``l_sole``, the hands); the tree's excluded
  pairs become contact excludes.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from robot.body.tree import BodyTree, Link, Shape
from sim.mujoco.mjcf_robot import fmt, sub

FOOT_ROLES = ("ankle_roll", "ankle_pitch")
LEG_ROLES = ("hip_yaw", "hip_roll", "hip_pitch")


def has_visuals(tree: BodyTree) -> bool:
    """True if any shape of ``tree`` is drawn only (the box model)."""
    return any(s.visual for link in tree.links for s in link.shapes)


def _subtree(tree: BodyTree, i: int) -> set[int]:
    return {k for k in range(len(tree.links)) if i in tree.chain(k)}


def _end_link(tree: BodyTree, side: str, roles: tuple[str, ...], *, nearest: bool
              ) -> int | None:
    """Of the links moved by ``roles`` on ``side``, the one nearest the torso (the leg's
    start) or, ``nearest`` False, the farthest (the foot)."""
    names = {f"{side}_{r}" for r in roles}
    links = [i for name, i in tree.joint_link.items() if name in names]
    if not links:
        return None
    depth = {i: len(tree.chain(i)) for i in links}
    return min(links, key=depth.__getitem__) if nearest else max(links, key=depth.__getitem__)


def add_worldbody(root: ET.Element, tree: BodyTree, *, childclass: str,
                  height0: float) -> None:
    """The ``worldbody`` of ``tree``, its torso ``height0`` [m] above the floor, every body
    in class ``childclass``; adds the hull meshes to ``<asset>`` (which must exist)."""
    leg_of: dict[int, str] = {}
    foot_of: dict[int, str] = {}
    for side in "rl":
        start = _end_link(tree, side, LEG_ROLES, nearest=True)
        foot = _end_link(tree, side, FOOT_ROLES, nearest=False)
        for i in _subtree(tree, start) if start is not None else ():
            leg_of[i] = f"{side}_leg"
        for i in _subtree(tree, foot) if foot is not None else ():
            foot_of[i] = side
    assets = root.find("asset")
    assert assets is not None
    drawn = not has_visuals(tree)
    feet = {"r": 0, "l": 0}
    names = {i: ("torso" if i == 0 else (link.name if link.name != "torso" else "torso_link"))
             for i, link in enumerate(tree.links)}
    elements: dict[int, ET.Element] = {}
    world = sub(root, "worldbody")
    for i, link in enumerate(tree.links):
        if i == 0:
            el = sub(world, "body", name="torso", pos=fmt(0, 0, height0), childclass=childclass)
            sub(el, "freejoint", name="root")
        else:
            el = sub(elements[link.parent], "body", name=names[i], pos=fmt(*link.pos),
                     quat=fmt(*link.quat))
        elements[i] = el
        _inertial(el, link)
        if link.joint is not None:
            h = link.joint
            sub(el, "joint", name=h.name, axis=fmt(*h.axis), pos=fmt(*h.pos),
                range=fmt(*h.range) if h.range is not None else "",
                ref=fmt(h.ref) if h.ref else "")
        contact = leg_of.get(i, "body")
        for k, shape in enumerate(link.shapes):
            name = shape.name
            if i in foot_of and not shape.visual:
                side = foot_of[i]
                name = f"{side}_foot" if feet[side] == 0 else f"{side}_foot_{feet[side]}"
                feet[side] += 1
            material = shape.material
            if drawn and not material:
                material = "foot" if i in foot_of else "link" if contact != "body" else "shell"
            _shape(el, assets, shape, name=name, cls="visual" if shape.visual else contact,
                   material=material, mesh=f"{names[i]}_{k}")
        for f in link.frames:
            sub(el, "site", name=f.name, pos=fmt(*f.pos), quat=fmt(*f.quat))
    if tree.excludes:
        contact_el = sub(root, "contact")
        for a, b in tree.excludes:
            sub(contact_el, "exclude", body1=names[tree.index[a]], body2=names[tree.index[b]])


def _inertial(el: ET.Element, link: Link) -> None:
    inert = link.inertial
    if inert is None:
        return
    ixx, iyy, izz, ixy, ixz, iyz = inert.inertia
    if ixy == ixz == iyz == 0.0:
        sub(el, "inertial", pos=fmt(*inert.com), mass=fmt(inert.mass),
            diaginertia=fmt(ixx, iyy, izz))
    else:
        sub(el, "inertial", pos=fmt(*inert.com), mass=fmt(inert.mass),
            fullinertia=fmt(ixx, iyy, izz, ixy, ixz, iyz))


def _shape(el: ET.Element, assets: ET.Element, shape: Shape, *, name: str, cls: str,
           material: str, mesh: str) -> None:
    attrs = {"name": name, "class_": cls, "pos": fmt(*shape.pos), "quat": fmt(*shape.quat),
             "material": material}
    if shape.kind == "hull":
        sub(assets, "mesh", name=mesh, vertex=fmt(*np.ravel(shape.vertices)))
        sub(el, "geom", type="mesh", mesh=mesh, **attrs)
    else:
        sub(el, "geom", type=shape.kind, size=fmt(*shape.size), **attrs)
