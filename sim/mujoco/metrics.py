"""Walk metrics from the simulated torso: distance, speed, drift, heading, fall detection."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

FALL_HEIGHT_RATIO = 0.5    # torso below this share of its standing height → fell
FALL_TILT_RAD = math.radians(45.0)


def yaw_of(quat_wxyz: Sequence[float] | np.ndarray) -> float:
    w, x, y, z = (float(v) for v in quat_wxyz)
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def tilt_of(quat_wxyz: Sequence[float]) -> float:
    """Angle between the body's z axis and world z [rad] for a (w, x, y, z) quaternion
    (not necessarily unit); as ``MujocoBus.upright_angle``."""
    w, x, y, z = quat_wxyz
    qn = w * w + x * x + y * y + z * z
    return math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (x * x + y * y) / qn)))


@dataclass
class WalkMonitor:
    """Fed once per tick with the sim bus; summarises the walk.

    standing_height: torso height above the floor when standing [m]; floor_normal: unit
    normal of the floor plane through the origin (a sloped world; the torso's height is
    measured along it). Positions are world x, y [m] (distance and drift: horizontal);
    yaw and tilt [rad] are the torso's (tilt: angle of its z axis from world z, gravity).
    """

    standing_height: float
    floor_normal: tuple[float, float, float] = (0.0, 0.0, 1.0)
    start_xy: tuple[float, float] | None = None
    start_yaw: float = 0.0
    last_xy: tuple[float, float] = (0.0, 0.0)
    last_yaw: float = 0.0
    heading: float = 0.0  # unwrapped yaw change since the start [rad]
    fell: bool = False
    fell_at: float | None = None
    min_height: float = math.inf
    max_tilt: float = 0.0
    stop_heading: float | None = None  # the heading it walked when told to stop [rad]
    stop_at: float | None = None
    _sum: float = 0.0          # the headings since a right touchdown [rad], summed
    _n: int = 0                # and counted
    _last_mean: float | None = None   # the mean heading of the last whole cycle [rad]

    def walking(self, right_landed: bool) -> None:
        """A walking tick (after ``update``): the heading joins the current cycle's, which
        ends when the right foot lands (``right_landed``)."""
        if right_landed and self._n:
            self._last_mean, self._sum, self._n = self._sum / self._n, 0.0, 0
        self._sum += self.heading
        self._n += 1

    def mark_stop(self, t: float) -> None:
        """The walk was told to stop at ``t`` [s] (its ramp-out begins). The heading it
        walked then is the mean over its last whole cycle (right touchdown to right
        touchdown; what it has if none: a walk's torso yaws back and forth with its
        steps, so the heading of one tick is not the walk's); the change from it to the
        end is the stop's."""
        if self.stop_heading is None:
            mean = (self._last_mean if self._last_mean is not None
                    else self._sum / self._n if self._n else self.heading)
            self.stop_heading, self.stop_at = mean, t

    def update_qpos(self, t: float, qpos: Sequence[float]) -> None:
        """``update`` from the free joint's qpos (x, y, z, qw, qx, qy, qz) as Python floats
        (one ``data.qpos[:7].tolist()`` per tick is cheaper than numpy views)."""
        x, y, z, qw, qx, qy, qz = qpos
        yaw = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
        self._update(t, x, y, z, yaw, tilt_of((qw, qx, qy, qz)))

    def update(self, t: float, pos: np.ndarray, quat: np.ndarray, tilt: float) -> None:
        """One tick at time ``t`` [s]: torso position ``pos`` [m], orientation ``quat``
        (w, x, y, z), ``tilt`` [rad]."""
        self._update(t, float(pos[0]), float(pos[1]), float(pos[2]), yaw_of(quat), tilt)

    def _update(self, t: float, x: float, y: float, z: float, yaw: float, tilt: float) -> None:
        if self.start_xy is None:
            self.start_xy = (x, y)
            self.start_yaw = self.last_yaw = yaw
        self.last_xy = (x, y)
        self.heading += math.atan2(math.sin(yaw - self.last_yaw), math.cos(yaw - self.last_yaw))
        self.last_yaw = yaw
        if self.floor_normal != (0.0, 0.0, 1.0):
            nx, ny, nz = self.floor_normal
            z = nx * x + ny * y + nz * z
        if z < self.min_height:
            self.min_height = z
        if tilt > self.max_tilt:
            self.max_tilt = tilt
        if not self.fell and (z < FALL_HEIGHT_RATIO * self.standing_height
                              or tilt > FALL_TILT_RAD):
            self.fell, self.fell_at = True, t

    def summary(self, walk_seconds: float) -> dict[str, Any]:
        start = self.start_xy if self.start_xy is not None else self.last_xy
        dx, dy = self.last_xy[0] - start[0], self.last_xy[1] - start[1]
        c, s = math.cos(self.start_yaw), math.sin(self.start_yaw)
        forward = c * dx + s * dy
        lateral = -s * dx + c * dy
        return {
            "distance_m": forward,
            "speed_m_s": forward / walk_seconds if walk_seconds > 0 else 0.0,
            "displacement_m": math.hypot(dx, dy),
            "lateral_drift_m": lateral,
            "heading_change_deg": math.degrees(self.heading),  # unwrapped: 2 turns = 720
            "fell": self.fell,
            "fell_at_s": self.fell_at,
            "min_torso_height_m": self.min_height,
            "max_tilt_deg": math.degrees(self.max_tilt),
            # The stop's own turn: from the stop request to the end (None: no stop).
            "stop_heading_change_deg": (None if self.stop_heading is None
                                        else math.degrees(self.heading - self.stop_heading)),
            "stop_at_s": self.stop_at,
        }
