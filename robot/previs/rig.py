"""An animated skeleton as read from a BVH or glTF file (robot/previs/bvh_read.py,
gltf_read.py), in the file's own axes and units, and which way is up in it.

Every bone's pose is a rotation relative to its rest orientation, in the axes of the
world at rest (``pose``): what a BVH channel set means directly; a glTF node with a rest
rotation is brought to the same form by ``Rig.from_local``. The robot frame (REP-103: x
forward, y left, z up) is found from the rest pose (``orient``): up is the skeleton's
longest extent, pointing away from the end with the feet (the end where more chain ends
lie; with none to tell, from the root toward the rest of the skeleton); left is the side
of the bones named left (``l_``, ``.L``, ``Left``...) or, with no such name, +X (Blender,
glTF and our own export all put the character's left on +X); forward completes a
right-handed frame.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from robot.errors import ConfigError

Array = npt.NDArray[np.float64]
#: A bone name that says it is on the left side.
LEFT = re.compile(r"(^l[_.\-]|[_.\-]l$|left)", re.IGNORECASE)
#: The share of the skeleton's height [1] within which a chain end counts as at an end.
END_BAND = 0.15
UPS = {"+x": (1, 0, 0), "-x": (-1, 0, 0), "+y": (0, 1, 0), "-y": (0, -1, 0),
       "+z": (0, 0, 1), "-z": (0, 0, -1)}


def nominal_frame_s(frame_s: float) -> float:
    """``frame_s`` [s] snapped to a whole frame rate when within 0.01 fps of one (a BVH
    writes 0.033333 for 30 fps; glTF stores times as float32)."""
    fps = 1.0 / frame_s
    return 1.0 / round(fps) if round(fps) >= 1 and abs(fps - round(fps)) < 0.01 else frame_s


@dataclass(frozen=True)
class Rig:
    """names: bones, parents before children; parents: index (-1: root); offsets (B, 3):
    each bone's rest position relative to its parent's [file units]; pose (n, B, 3, 3):
    each bone's rotation relative to its parent's, from rest, in world-rest axes; root
    (n, 3): the root's position [file units]; frame_s: time per frame [s]; ends: chain
    end sites (parent index, offset) that have no bone of their own; sampled: the frames
    sample a curve (a BVH's, a glTF's LINEAR tracks), not sparse keyframes (a glTF's
    CUBICSPLINE or STEP tracks): the import interpolates them with the spline."""

    names: tuple[str, ...]
    parents: tuple[int, ...]
    offsets: Array
    pose: Array
    root: Array
    frame_s: float
    ends: tuple[tuple[int, tuple[float, float, float]], ...] = ()
    source: str = "<memory>"
    sampled: bool = True

    @staticmethod
    def from_local(names: tuple[str, ...], parents: tuple[int, ...], offsets: Array,
                   rest: Array, local: Array, root: Array, frame_s: float, *,
                   ends: tuple[tuple[int, tuple[float, float, float]], ...] = (),
                   source: str = "<memory>", sampled: bool = True) -> Rig:
        """From node rotations as a glTF file animates them: ``rest`` (B, 3, 3) each
        node's rest rotation relative to its parent, ``local`` (n, B, 3, 3) the animated
        ones. The pose in world-rest axes is W0p L L0^-1 W0p^-1 (W0p: the parent's rest
        orientation in the world); offsets are turned into world-rest axes too."""
        world = np.zeros_like(rest)
        pose = np.empty_like(local)
        flat = np.empty_like(offsets)
        for b, p in enumerate(parents):
            wp = world[p] if p >= 0 else np.eye(3)
            world[b] = wp @ rest[b]
            flat[b] = wp @ offsets[b]
            pose[:, b] = wp @ local[:, b] @ rest[b].T @ wp.T
        flat_ends = tuple((p, tuple(float(v) for v in world[p] @ np.asarray(o)))
                          for p, o in ends)
        return Rig(names, parents, flat, pose, root, frame_s, flat_ends,  # type: ignore[arg-type]
                   source, sampled)

    @property
    def frames(self) -> int:
        return len(self.pose)

    def rest_positions(self) -> tuple[Array, Array]:
        """World rest positions of the bones (B, 3) and of the end sites (E, 3)."""
        pos = np.zeros((len(self.names), 3))
        for b, p in enumerate(self.parents):
            pos[b] = (pos[p] if p >= 0 else 0.0) + self.offsets[b]
        ends = np.array([pos[p] + np.asarray(o) for p, o in self.ends]).reshape(-1, 3)
        return pos, ends

    def leaves(self) -> Array:
        """Rest positions of every chain end: end sites and bones with no child."""
        pos, ends = self.rest_positions()
        has_child = {p for p in self.parents if p >= 0} | {p for p, _ in self.ends}
        tips = [pos[b] for b in range(len(self.names)) if b not in has_child]
        return np.vstack([ends, np.array(tips).reshape(-1, 3)])

    def up(self) -> Array:
        """The up direction (3,) in file axes, detected from the rest pose."""
        pos, ends = self.rest_positions()
        every = np.vstack([pos, ends])
        extent = every.max(axis=0) - every.min(axis=0)
        k = int(np.argmax(extent))
        h = every[:, k]
        tips = self.leaves()[:, k]
        band = END_BAND * extent[k]
        low = int(np.sum(tips <= h.min() + band))
        high = int(np.sum(tips >= h.max() - band))
        out = np.zeros(3)
        if low != high:
            out[k] = 1.0 if low > high else -1.0
            return out
        # No feet to tell (an upper body alone): up is from the root toward the rest.
        lean = float(np.mean(h) - pos[0, k])
        if abs(lean) < 1e-9 * max(extent[k], 1e-12):
            raise ConfigError(f"{self.source}: cannot tell up from down in the rest pose "
                              f"({low} chain ends at each end of axis {'XYZ'[k]}); give "
                              "--up (+x, -x, +y, -y, +z or -z)")
        out[k] = 1.0 if lean > 0 else -1.0
        return out

    def orient(self, up: str | None = None) -> Array:
        """C (3, 3) with v_robot = C @ v_file: rows forward, left, up in file axes."""
        u = np.asarray(UPS[up], dtype=float) if up else self.up()
        pos, _ = self.rest_positions()
        lefts = [b for b, n in enumerate(self.names) if LEFT.search(n)]
        side = np.zeros(3)
        if lefts:
            side = pos[lefts].mean(axis=0) - pos.mean(axis=0)
            side -= u * (side @ u)
        if np.linalg.norm(side) < 1e-9:
            side = np.array([1.0, 0.0, 0.0])
            side -= u * (side @ u)
        if np.linalg.norm(side) < 1e-9:   # +X is up: the left is then +Y
            side = np.array([0.0, 1.0, 0.0])
        k = int(np.argmax(np.abs(side)))
        left = np.zeros(3)
        left[k] = np.sign(side[k])
        forward = np.cross(left, u)
        return np.vstack([forward, left, u])
