"""Where an animated skeleton's feet and root go, frame by frame: forward kinematics of the
rig (robot/previs/rig.py) in robot axes (x forward, y left, z up), scaled to the robot.

A bone's world rotation is its parent's times its own pose (poses are rotations from rest
in world-rest axes, so the rest orientation is the identity); its position is the
parent's plus the parent's world rotation applied to its rest offset; a chain end (an end
site, or a bone with no child) likewise. The feet are the chain ends within ``END_BAND``
of the skeleton's height above its lowest one at rest (the rule that finds up,
robot/previs/rig.py), right of the root (y < 0) or left of it; each foot's point in a
frame is its lowest such end then (a heel, a toe or a sole), so a foot that rolls from
heel to toe is followed by the end that carries it. The heading is the root bone's yaw
(its forward axis about up), unwrapped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robot.previs.rig import END_BAND, Array, Rig


@dataclass(frozen=True)
class RigMotion:
    """t (n,) [s]; feet (2, n, 3): the right and left foot's lowest point [m]; foot_speed
    (2, n): that point's horizontal speed [m/s]; root (n, 3) [m], heading (n,) [rad]; all
    in robot axes, scaled to the robot (lengths x ``scale``); feet_found: the rig has a
    foot on each side."""

    t: Array
    feet: Array
    foot_speed: Array
    root: Array
    heading: Array
    feet_found: bool


def _world(rig: Rig) -> tuple[Array, Array, Array]:
    """World rotations (n, B, 3, 3), bone positions (n, B, 3) and chain-end positions
    (n, E, 3) in file axes and units, ends in ``Rig.leaves`` order."""
    n, nb = rig.frames, len(rig.names)
    rot = np.empty((n, nb, 3, 3))
    pos = np.empty((n, nb, 3))
    for b, p in enumerate(rig.parents):
        if p < 0:
            rot[:, b] = rig.pose[:, b]
            pos[:, b] = rig.root
        else:
            rot[:, b] = rot[:, p] @ rig.pose[:, b]
            pos[:, b] = pos[:, p] + rot[:, p] @ rig.offsets[b]
    has_child = {p for p in rig.parents if p >= 0} | {p for p, _ in rig.ends}
    ends = [pos[:, p] + rot[:, p] @ np.asarray(o) for p, o in rig.ends]
    ends += [pos[:, b] for b in range(nb) if b not in has_child]
    return rot, pos, np.stack(ends, axis=1) if ends else np.zeros((n, 0, 3))


def rig_motion(rig: Rig, c: Array, scale: float) -> RigMotion:
    """The feet, root and heading of ``rig`` seen through ``c`` (robot from file axes,
    ``Rig.orient``), lengths times ``scale`` [m per file unit]."""
    rot, _, ends = _world(rig)
    t: Array = np.arange(rig.frames, dtype=np.float64) * rig.frame_s
    root = rig.root @ c.T * scale
    fwd = np.einsum("ij,njk,k->ni", c, rot[:, 0], c[0])     # the root's forward, robot axes
    heading = np.unwrap(np.arctan2(fwd[:, 1], fwd[:, 0]))
    leaves = rig.leaves() @ c.T
    rest_root = rig.rest_positions()[0][0] @ c.T
    every = np.vstack([rig.rest_positions()[0] @ c.T, leaves])
    height = float(np.ptp(every[:, 2])) if len(every) else 0.0
    low = leaves[:, 2] <= leaves[:, 2].min() + END_BAND * height if len(leaves) else \
        np.zeros(0, dtype=bool)
    sides = [np.flatnonzero(low & (leaves[:, 1] < rest_root[1])),
             np.flatnonzero(low & (leaves[:, 1] > rest_root[1]))]
    n = rig.frames
    feet = np.zeros((2, n, 3))
    speed = np.zeros((2, n))
    found = all(len(s) for s in sides)
    if found:
        pts = ends @ c.T * scale                                   # (n, E, 3)
        vel = np.gradient(pts[..., :2], rig.frame_s, axis=0) if n > 1 else np.zeros_like(
            pts[..., :2])
        frames = np.arange(n)
        for k, idx in enumerate(sides):
            lowest = idx[np.argmin(pts[:, idx, 2], axis=1)]
            feet[k] = pts[frames, lowest]
            speed[k] = np.linalg.norm(vel[frames, lowest], axis=1)
    return RigMotion(t, feet, speed, root, heading, found)
