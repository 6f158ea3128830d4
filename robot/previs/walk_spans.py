"""Where an animation walks: spans in which the feet are planted in turn while the root
travels or turns (the feet and root from robot/previs/feet.py, on the robot's scale).

The criterion, each threshold a share of the robot's leg length L (thigh + shin + ankle
height), so it means the same for a character of any size once scaled to the robot:

1. A foot is *planted* in a frame when its lowest point is within ``PLANT_HEIGHT`` L of
   the floor (the lowest either foot reaches over the whole animation: a level floor the
   character stands on) and moves slower than ``PLANT_SPEED`` L/s over the ground.
2. A *swing* (one step) is a run of frames, at least ``MIN_SWING_S`` long, in which a foot
   is not planted while the other one is for at least half of that run (single support:
   a jump, both feet up, is not a step).
3. A *walk* is a chain of at least two swings that alternate feet (right, left, right...
   or left first), each starting at most ``MAX_STEP_GAP_S`` after the one before ended;
   two swings of one foot in a row, or a longer pause, end the chain.
4. It walks only if the root goes somewhere: at least ``MIN_ADVANCE`` L over the ground or
   ``MIN_TURN`` rad of heading per step, on average over the chain; less is stepping in
   place, which the animation's own legs keep doing.

A walk spans from its first swing's lift-off to its last swing's touch-down.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robot.previs.feet import RigMotion
from robot.previs.rig import Array

PLANT_HEIGHT = 0.05        # [L] above the floor
PLANT_SPEED = 0.25         # [L/s] over the ground
MIN_SWING_S = 0.08         # [s]
MAX_STEP_GAP_S = 1.0       # [s] from one swing's end to the next one's start
MIN_ADVANCE = 0.05         # [L per step]
MIN_TURN = 0.05            # [rad per step]
FEET = ("right", "left")


@dataclass(frozen=True)
class Swing:
    """A step: ``foot`` 0 (right) or 1 (left) in the air from ``start`` to ``end`` [s]."""

    foot: int
    start: float
    end: float


@dataclass(frozen=True)
class Walk:
    """A span that walks: from ``start`` to ``end`` [s], its ``swings`` in order."""

    start: float
    end: float
    swings: tuple[Swing, ...]


def planted(m: RigMotion, leg: float) -> Array:
    """(2, n) bool: each foot planted in each frame (criterion 1)."""
    floor = float(m.feet[:, :, 2].min())
    low = m.feet[:, :, 2] - floor <= PLANT_HEIGHT * leg
    return np.asarray(low & (m.foot_speed <= PLANT_SPEED * leg))


def _runs(mask: Array) -> list[tuple[int, int]]:
    """Maximal runs of True in ``mask`` as [i, j) index pairs."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(np.int8), [0]])))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True))


def swings(m: RigMotion, leg: float) -> list[Swing]:
    """Every step of the animation in time order (criterion 2)."""
    down = planted(m, leg)
    t, dt = m.t, (m.t[1] - m.t[0]) if len(m.t) > 1 else 1.0
    found: list[Swing] = []
    for foot in (0, 1):
        for i, j in _runs(~down[foot]):
            if (j - i) * dt >= MIN_SWING_S and down[1 - foot, i:j].mean() >= 0.5:
                found.append(Swing(foot, float(t[i]), float(t[min(j, len(t) - 1)])))
    return sorted(found, key=lambda s: s.start)


def walks(m: RigMotion, leg: float) -> tuple[Walk, ...]:
    """The spans that walk (criteria 3 and 4); none if the rig has no feet to tell."""
    if not m.feet_found or len(m.t) < 3:
        return ()
    chains: list[list[Swing]] = []
    for s in swings(m, leg):
        last = chains[-1][-1] if chains else None
        if last is not None and s.foot != last.foot and s.start - last.end <= MAX_STEP_GAP_S:
            chains[-1].append(s)
        else:
            chains.append([s])
    out = []
    for chain in chains:
        if len(chain) < 2:
            continue
        i, j = (int(np.searchsorted(m.t, x)) for x in (chain[0].start, chain[-1].end))
        j = min(j, len(m.t) - 1)
        advance = float(np.linalg.norm(m.root[j, :2] - m.root[i, :2]))
        turn = abs(float(m.heading[j] - m.heading[i]))
        steps = len(chain)
        if advance >= MIN_ADVANCE * leg * steps or turn >= MIN_TURN * steps:
            out.append(Walk(chain[0].start, chain[-1].end, tuple(chain)))
    return tuple(out)
