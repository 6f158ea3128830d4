"""Radians ↔ ticks per servo: the only place (with the buses) that knows a tick.

ticks = zero_ticks + sign * q * ticks_per_rad, rounded (ticks_per_rad = resolution / span:
resolution / (2 pi) for full-turn servos, 1024 / (300 deg) for the AX series), inside the tick limits that
the joint limits imply.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import NoReturn

import numpy as np
import numpy.typing as npt

from robot.config.robot import RobotConfig
from robot.errors import BipedError
from robot.servo import ticks as tick_math


class ServoMap:
    """Vectorised joint-angle ↔ goal-tick conversion for one robot.

    Arrays are ordered like ``robot.joints``.
    """

    def __init__(self, robot: RobotConfig) -> None:
        self.names: tuple[str, ...] = robot.joint_names
        self.ids: tuple[int, ...] = robot.ids
        #: ticks per turn of each joint's servo (a robot may mix models)
        self.resolution = np.array([robot.servo(j).resolution for j in robot.joints])
        self.ticks_per_rad = np.array([robot.servo(j).ticks_per_rad for j in robot.joints])
        self.sign = np.array([j.sign for j in robot.joints], dtype=float)
        self.zero = np.array([j.zero_ticks for j in robot.joints], dtype=float)
        self.q_min = np.array([j.min_rad for j in robot.joints])
        self.q_max = np.array([j.max_rad for j in robot.joints])
        self.max_speed = np.array([j.max_speed_rad_s for j in robot.joints])
        # Tick limits: the ticks strictly inside [q_min, q_max] after rounding.
        self.tick_min, self.tick_max = tick_math.tick_range(self.zero, self.sign, self.ticks_per_rad,
                                                        self.q_min, self.q_max)
        self._rows = list(zip(self.ids, self.zero.tolist(),
                              (self.sign * self.ticks_per_rad).tolist(),
                              self.tick_min.tolist(), self.tick_max.tolist(), strict=True))
        self._gain = self.sign * self.ticks_per_rad  # [ticks/rad]
        self._tick_lo, self._tick_hi = self.tick_min.astype(float), self.tick_max.astype(float)
        self._index = {n: i for i, n in enumerate(self.names)}
        self._id_index = {sid: i for i, sid in enumerate(self.ids)}

    def index(self, name: str) -> int:
        return self._index[name]

    def clamp(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Joint angles clipped to the joint limits [rad]."""
        return np.asarray(q, dtype=float).clip(self.q_min, self.q_max)

    def to_ticks(self, q: npt.ArrayLike) -> npt.NDArray[np.int64]:
        """Joint angles [rad] → goal ticks, clamped to the limits (never outside them).

        Clamped before the integer cast, so huge or infinite angles land on the right
        limit; NaN raises BipedError naming the joint.
        """
        with np.errstate(over="ignore"):  # huge angles become ±inf, then clamp
            raw = self.zero + self.sign * np.asarray(q, dtype=float) * self.ticks_per_rad
        if np.isnan(raw).any():
            self._nan(int(np.flatnonzero(np.isnan(raw))[0]) % len(self.names))
        return np.rint(np.clip(raw, self.tick_min, self.tick_max)).astype(np.int64)

    def _nan(self, i: int) -> NoReturn:
        raise BipedError(f"servo_map: joint {self.names[i]} (servo id {self.ids[i]}): goal "
                         "angle is NaN; refusing to send it")

    def to_rad(self, ticks: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Ticks → joint angles [rad] (not clamped: a read-back may be outside limits)."""
        return tick_math.to_rad(ticks, self.zero, self.sign, self.ticks_per_rad)

    def goals(self, q: Sequence[float]) -> dict[int, int]:
        """Joint angles [rad] → ``{servo_id: ticks}`` ready for ``Bus.write_goals``,
        clamped to the tick limits. Pure Python: this runs every control tick."""
        out: dict[int, int] = {}
        for i, ((sid, zero, gain, lo, hi), v) in enumerate(zip(self._rows, q, strict=True)):
            t = zero + gain * v  # clamp before round(): round(inf) raises
            if t != t:
                self._nan(i)
            out[sid] = lo if t < lo else hi if t > hi else round(t)
        return out

    def tick_vector(self, q: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """``goals`` as one array in joint order: the same goal ticks, whole numbers as
        floats (numpy's rint rounds half to even, as ``round``); NaN raises BipedError
        naming the joint."""
        t = self.zero + self._gain * q
        ticks: npt.NDArray[np.float64] = np.rint(t.clip(self._tick_lo, self._tick_hi))
        total = np.add.reduce(ticks)     # finite unless a tick is NaN (the rest are clamped)
        if total != total:
            self._nan(int(np.flatnonzero(t != t)[0]))
        return ticks

    def from_positions(self, positions: Mapping[int, int]) -> npt.NDArray[np.float64]:
        """``{servo_id: ticks}`` (all ids) → joint angles [rad] in joint order."""
        return self.to_rad([positions[i] for i in self.ids])

    def vector(self, pose: Mapping[str, float], *, default: float = 0.0) -> npt.NDArray[np.float64]:
        """A ``{joint: rad}`` mapping → an array in joint order (missing joints = default)."""
        return np.array([pose.get(n, default) for n in self.names], dtype=float)

    def named(self, q: Sequence[float] | npt.NDArray[np.float64]) -> dict[str, float]:
        return {n: float(v) for n, v in zip(self.names, q, strict=True)}
