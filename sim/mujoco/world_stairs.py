"""Stairs in the MuJoCo scene (``World.stairs_height_m``, ``World.stairs_count``,
``World.stairs_tread_m``): a flight of N steps up, a landing, a flight of N steps down,
straight ahead of the robot.

Floor frame (x forward from the start pose's ankles, z up from the floor): the first riser
stands at ``STAIRS_X0_M`` (22 cm ahead of the 18-joint robots' toes: the gait has ramped in
when it gets there); every tread is T deep (``World.stairs_tread_m``, default
``robot.config.world.STAIRS_TREAD_M``, 0.25 m), the landing at the top
``STAIR_LANDING_M``; the stairs span
``|y| <= STAIRS_HALF_WIDTH_M``. Each step is a box stacked on the one below, k = 1..N:
from z = (k - 1) H to k H, and from x = x0 + (k - 1) T to x0 + (k - 1) T + 2 (N - k) T + L,
so the ground under the robot is k H between the k-th riser up and the k-th riser down.
"""

from __future__ import annotations

from dataclasses import dataclass

from robot.config.world import STAIRS_TREAD_M

STAIRS_X0_M = 0.30
STAIR_LANDING_M = 0.30
STAIRS_HALF_WIDTH_M = 0.5


@dataclass(frozen=True)
class StairBox:
    """One step: x from ``x0`` to ``x1``, z from ``z0`` to ``z1`` (floor frame) [m]."""

    x0: float
    x1: float
    z0: float
    z1: float

    @property
    def centre(self) -> tuple[float, float, float]:
        return ((self.x0 + self.x1) / 2, 0.0, (self.z0 + self.z1) / 2)

    @property
    def half_sides(self) -> tuple[float, float, float]:
        return ((self.x1 - self.x0) / 2, STAIRS_HALF_WIDTH_M, (self.z1 - self.z0) / 2)


def stair_boxes(height: float, count: int, tread: float = STAIRS_TREAD_M) -> list[StairBox]:
    """The ``count`` stacked boxes of steps ``height`` [m] high, treads ``tread`` [m] deep
    (module docstring)."""
    out = []
    for k in range(1, count + 1):
        x0 = STAIRS_X0_M + (k - 1) * tread
        width = 2 * (count - k) * tread + STAIR_LANDING_M
        out.append(StairBox(x0, x0 + width, (k - 1) * height, k * height))
    return out


def stairs_end_m(count: int, tread: float = STAIRS_TREAD_M) -> float:
    """x of the last riser down [m]: past it the floor is flat again."""
    return STAIRS_X0_M + 2 * (count - 1) * tread + STAIR_LANDING_M
