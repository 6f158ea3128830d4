"""Checking an imported joint stream against the robot before it becomes a take: every
joint-limit, speed and acceleration violation with its time and joint, and the stream
clamped so that none is left.

Limits: the joint's ``min_rad``/``max_rad`` and ``max_speed_rad_s`` from the robot file;
acceleration: ``max_speed_rad_s / ACCEL_RISE_S`` (full slew speed reached in 10 ms) unless
given. The bundled gaits, sampled at 30 fps as `biped export` writes them, peak at about
210 rad/s^2 (the walk's knee): under the default 500 rad/s^2 of a 5 rad/s joint; what
goes beyond is a snap no servo follows (the hold torque, not the motion, then decides).
Speed and acceleration are finite differences over the stream's ticks. The clamp runs
forward in time: each tick's velocity change is limited to the acceleration, its velocity
to the speed and to what the acceleration can stop before a joint limit, its angle to the
limits; a clamped joint lags the animation and catches up where the animation allows.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from robot.config.robot import RobotConfig
from robot.previs.rig import Array

#: Time to reach a joint's max speed from rest at the default acceleration limit [s].
ACCEL_RISE_S = 0.01
KINDS = ("limit", "speed", "accel")
UNITS = {"limit": "rad", "speed": "rad/s", "accel": "rad/s^2"}


@dataclass(frozen=True)
class Violation:
    """One stretch [t0, t1] [s] where ``joint`` exceeds its ``kind`` limit; ``worst``:
    the largest excess value (in the kind's unit), at ``t_worst`` [s]; ``bound``: the limit."""

    joint: str
    kind: str
    t0: float
    t1: float
    worst: float
    t_worst: float
    bound: float

    def line(self) -> str:
        unit = UNITS[self.kind]
        span = (f"t={self.t0:.3f} s" if self.t1 - self.t0 < 1e-9
                else f"t={self.t0:.3f}-{self.t1:.3f} s")
        return (f"{span:<22} {self.joint:<18} {self.kind:<6} {self.worst:+.3f} {unit} "
                f"(limit {self.bound:.3f}) at t={self.t_worst:.3f} s")


def _runs(mask: npt.NDArray[np.bool_]) -> list[tuple[int, int]]:
    """Start and end index (inclusive) of each run of True."""
    m = np.concatenate([[False], mask.astype(bool), [False]])
    d = np.diff(m.astype(int))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1, strict=True))


def accel_limits(robot: RobotConfig, max_accel: float | None = None) -> Array:
    """Per-joint acceleration limit [rad/s^2]."""
    speed = np.array([j.max_speed_rad_s for j in robot.joints])
    return np.full(len(speed), max_accel) if max_accel else speed / ACCEL_RISE_S


def check(robot: RobotConfig, t: Array, q: Array, *, max_accel: float | None = None,
          joints: tuple[str, ...] | None = None) -> list[Violation]:
    """Every violation in the stream ``q`` (n, joints) [rad] at ``t`` (n,) [s], by time;
    ``joints``: check only these (default: all)."""
    out: list[Violation] = []
    dt = np.diff(t)
    v = np.diff(q, axis=0) / dt[:, None] if len(t) > 1 else np.zeros((0, q.shape[1]))
    a = np.diff(v, axis=0) / dt[1:, None] if len(t) > 2 else np.zeros((0, q.shape[1]))
    amax = accel_limits(robot, max_accel)
    for col, j in enumerate(robot.joints):
        if joints is not None and j.name not in joints:
            continue
        x = q[:, col]
        over = np.maximum(x - j.max_rad, j.min_rad - x)
        series = (("limit", over, x, t, None), ("speed", np.abs(v[:, col]) - j.max_speed_rad_s,
                                                v[:, col], t[1:], j.max_speed_rad_s),
                  ("accel", np.abs(a[:, col]) - amax[col], a[:, col], t[2:], amax[col]))
        for kind, excess, value, times, bound in series:
            for i0, i1 in _runs(excess > 1e-9):
                k = i0 + int(np.argmax(excess[i0:i1 + 1]))
                lim = bound if bound is not None else (j.max_rad if value[k] > j.max_rad
                                                       else j.min_rad)
                out.append(Violation(j.name, kind, float(times[i0]), float(times[i1]),
                                     float(value[k]), float(times[k]), float(lim)))
    return sorted(out, key=lambda w: (w.t0, w.joint))


def clamp(robot: RobotConfig, t: Array, q: Array, *,
          max_accel: float | None = None) -> Array:
    """The stream with every violation clamped (forward in time; see the module doc)."""
    lo = np.array([j.min_rad for j in robot.joints])
    hi = np.array([j.max_rad for j in robot.joints])
    vmax = np.array([j.max_speed_rad_s for j in robot.joints])
    amax = accel_limits(robot, max_accel)
    out = np.empty_like(q)
    out[0] = np.clip(q[0], lo, hi)
    v = np.zeros(q.shape[1])
    for k in range(1, len(q)):
        h = t[k] - t[k - 1]
        want = (np.clip(q[k], lo, hi) - out[k - 1]) / h
        want = np.clip(want, v - amax * h, v + amax * h)
        # No faster than the acceleration can stop in before a joint limit.
        room_hi = np.maximum(hi - out[k - 1], 0.0)
        room_lo = np.maximum(out[k - 1] - lo, 0.0)
        half = amax * h / 2
        v = np.clip(want, -np.minimum(vmax, np.sqrt(half**2 + 2 * amax * room_lo) - half),
                    np.minimum(vmax, np.sqrt(half**2 + 2 * amax * room_hi) - half))
        out[k] = np.clip(out[k - 1] + v * h, lo, hi)
        v = (out[k] - out[k - 1]) / h
    return out
