"""Walk metrics from the simulated torso: distance, speed, drift, heading, fall detection."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

FALL_HEIGHT_RATIO = 0.5    # torso below this share of its standing height → fell
FALL_TILT_RAD = math.radians(45.0)


def yaw_of(quat_wxyz: np.ndarray) -> float:
    w, x, y, z = (float(v) for v in quat_wxyz)
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


@dataclass
class WalkMonitor:
    """Fed once per tick with the sim bus; summarises the walk.

    standing_height: torso height when standing [m].
    """

    standing_height: float
    start_xy: np.ndarray | None = None
    start_yaw: float = 0.0
    last_xy: np.ndarray = field(default_factory=lambda: np.zeros(2))
    last_yaw: float = 0.0
    heading: float = 0.0  # unwrapped yaw change since the start [rad]
    fell: bool = False
    fell_at: float | None = None
    min_height: float = math.inf
    max_tilt: float = 0.0

    def update(self, t: float, pos: np.ndarray, quat: np.ndarray, tilt: float) -> None:
        if self.start_xy is None:
            self.start_xy = pos[:2].copy()
            self.start_yaw = self.last_yaw = yaw_of(quat)
        self.last_xy = pos[:2].copy()
        yaw = yaw_of(quat)
        self.heading += math.atan2(math.sin(yaw - self.last_yaw), math.cos(yaw - self.last_yaw))
        self.last_yaw = yaw
        self.min_height = min(self.min_height, float(pos[2]))
        self.max_tilt = max(self.max_tilt, tilt)
        if not self.fell and (pos[2] < FALL_HEIGHT_RATIO * self.standing_height
                              or tilt > FALL_TILT_RAD):
            self.fell, self.fell_at = True, t

    def summary(self, walk_seconds: float) -> dict[str, Any]:
        start = self.start_xy if self.start_xy is not None else self.last_xy
        d = self.last_xy - start
        c, s = math.cos(self.start_yaw), math.sin(self.start_yaw)
        forward = float(c * d[0] + s * d[1])
        lateral = float(-s * d[0] + c * d[1])
        return {
            "distance_m": forward,
            "speed_m_s": forward / walk_seconds if walk_seconds > 0 else 0.0,
            "displacement_m": float(np.hypot(*d)),
            "lateral_drift_m": lateral,
            "heading_change_deg": math.degrees(self.heading),  # unwrapped: 2 turns = 720
            "fell": self.fell,
            "fell_at_s": self.fell_at,
            "min_torso_height_m": self.min_height,
            "max_tilt_deg": math.degrees(self.max_tilt),
        }
