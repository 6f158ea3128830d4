"""Where the body stands over its feet, from the legs' joint angles and the torso's tilt:
the kinematic half of the capture point (issue 22, third pass).

The torso's tilt alone cannot say where the body stands over a foot that landed out of
its place (docs/robustness.md, issue 22, second pass): a position-controlled leg carries
the pelvis wherever its joint angles put it. Here each sole is found under the pelvis by
the legs' forward kinematics (robot.gait.ik.leg_fk_full) of the joint angles the servos
hold, turned from the pelvis frame into a level, yaw-free frame by the IMU's roll and
pitch; the pelvis then stands at minus that over each sole. Its velocity over a sole is
the change of that position over one tick with the same sole as reference, so a change
of stance foot is no jump. With the feet flat on the ground this is the body's own
horizontal position and velocity relative to its support, the inputs of the capture point
xi = c + c' / omega0 (Pratt et al. 2006; the stance-foot frame as in Englsberger et al.
2015), measured with what a real robot has (present positions, an IMU).

Signs: REP-103 (x forward, y left); +pitch nose down, +roll right side down (the law's
convention, robot.balance.law). Units: m, m/s, rad.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from math import cos, sin
from typing import NamedTuple

from robot.config.joint_names import LEG_JOINTS
from robot.config.robot import Geometry
from robot.gait.ik import hip_centre

Point = tuple[float, float, float]
Quad = tuple[float, float, float, float]
Plane = tuple[float, float]


class LegSlots(NamedTuple):
    """Indices of each leg's six joints (LEG_JOINTS order) in a robot's joint vector;
    None for a joint the robot lacks (hip yaw on 5-DoF legs: held at 0)."""

    right: tuple[int | None, ...]
    left: tuple[int | None, ...]

    @classmethod
    def of(cls, joint_names: Sequence[str]) -> LegSlots:
        index = {n: i for i, n in enumerate(joint_names)}
        return cls(tuple(index.get(f"r_{j}") for j in LEG_JOINTS),
                   tuple(index.get(f"l_{j}") for j in LEG_JOINTS))


def leg_angles(q: Sequence[float], slots: tuple[int | None, ...]) -> tuple[float, ...]:
    """The six angles [rad] of one leg from the joint vector ``q``; 0 where it has none."""
    return tuple([0.0 if i is None else float(q[i]) for i in slots])


def level(v: tuple[float, float, float], roll: float, pitch: float
          ) -> tuple[float, float, float]:
    """Vector ``v`` [m] of the pelvis frame in the level frame: R_y(pitch) R_x(roll) v."""
    return _level(v, math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch))


def _level(v: tuple[float, float, float], cr: float, sr: float, cp: float, sp: float
           ) -> tuple[float, float, float]:
    """``level`` with the cosines and sines of roll and pitch given."""
    x, y, z = v
    y, z = cr * y - sr * z, sr * y + cr * z
    return cp * x + sp * z, y, -sp * x + cp * z


Legs = tuple[Sequence[float], Sequence[float]]
#: The right and left sole points [m] in the pelvis frame for (right, left) leg angles.
SolesOf = Callable[[Legs], tuple[Point, Point]]


def sole_point(g: Geometry, side: str, q: Sequence[float]) -> Point:
    """The sole point [m] of ``robot.gait.ik.leg_fk_full`` for six leg angles [rad] on
    Python floats: its operations written out, those of the foot's rotation that the
    point does not use left out (the same bits: tests/test_kinematic_sole.py)."""
    hx, hy, hz = hip_centre(g, side)
    q0, q1, q2, q3, q4, q5 = q
    c, s = cos(q0), sin(q0)                                       # rot_z
    r0, r1, r2, r3, r4, r5, r6, r7, r8 = c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0
    c, s = cos(q1), sin(q1)                                       # post_rx
    r1, r2, r4, r5, r7, r8 = (c * r1 + s * r2, c * r2 - s * r1, c * r4 + s * r5,
                              c * r5 - s * r4, c * r7 + s * r8, c * r8 - s * r7)
    c, s = cos(q2), sin(q2)                                       # post_ry: the hip
    h0, h2, h3, h5, h6, h8 = (c * r0 - s * r2, s * r0 + c * r2, c * r3 - s * r5,
                              s * r3 + c * r5, c * r6 - s * r8, s * r6 + c * r8)
    c, s = cos(q3), sin(q3)                                       # post_ry: the knee
    k0, k2, k3, k5, k6, k8 = (c * h0 - s * h2, s * h0 + c * h2, c * h3 - s * h5,
                              s * h3 + c * h5, c * h6 - s * h8, s * h6 + c * h8)
    c, s = cos(q4), sin(q4)                                       # post_ry, column 2
    a2, a5, a8 = s * k0 + c * k2, s * k3 + c * k5, s * k6 + c * k8
    c, s = cos(q5), sin(q5)                                       # post_rx, column 2
    f2, f5, f8 = c * a2 - s * r1, c * a5 - s * r4, c * a8 - s * r7
    ah = g.ankle_height
    return (hx - h2 * g.thigh - k2 * g.shin - f2 * ah, hy - h5 * g.thigh - k5 * g.shin - f5 * ah,
            hz - h8 * g.thigh - k8 * g.shin - f8 * ah)


def leg_soles(g: Geometry, legs: Legs) -> tuple[Point, Point]:
    """The right and left sole points [m] in the pelvis frame (the legs' forward
    kinematics, ``sole_point``) for the (right, left) leg angles [rad]."""
    return sole_point(g, "r", legs[0]), sole_point(g, "l", legs[1])


class SoleMemo:
    """``leg_soles`` of one geometry, remembered for one tick: the estimate asks for each
    pose of the legs twice, at its tick and as the tick before at the next (the same
    numbers: the kinematics is a function of the angles). ``tick()`` starts a tick."""

    def __init__(self, g: Geometry) -> None:
        self.g = g
        self._now: dict[Legs, tuple[Point, Point]] = {}
        self._last: dict[Legs, tuple[Point, Point]] = {}

    def tick(self) -> None:
        self._last, self._now = self._now, {}

    def __call__(self, legs: Legs) -> tuple[Point, Point]:
        got = self._now.get(legs) or self._last.get(legs)
        if got is None:
            got = leg_soles(self.g, legs)
        self._now[legs] = got
        return got


def over_soles(soles: tuple[Point, Point], roll: float, pitch: float
               ) -> tuple[Point, Point]:
    """The pelvis's position (forward, left, up) [m] relative to the right and to the
    left sole point (pelvis frame), level frame, for the torso tilt [rad]."""
    cs = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    out = []
    for sole in soles:
        x, y, z = _level((float(sole[0]), float(sole[1]), float(sole[2])), *cs)
        out.append((-x, -y, -z))
    return out[0], out[1]


def body_over_soles(g: Geometry, q_right: Sequence[float], q_left: Sequence[float],
                    roll: float, pitch: float) -> tuple[Point, Point]:
    """The pelvis's position (forward, left, up) [m] relative to the right and to the
    left sole point, level frame, for leg angles [rad] and torso tilt [rad]."""
    return over_soles(leg_soles(g, (q_right, q_left)), roll, pitch)


def support_weight(standing: tuple[bool, bool]) -> float:
    """The right sole's share of the support [0, 1]: 1 when only it stands, 0 when only
    the left one does, 0.5 when both or neither do."""
    r, l_ = standing
    return 1.0 if r and not l_ else 0.0 if l_ and not r else 0.5


def over_support(g: Geometry, legs: Legs, before: Legs | None, tilt: Quad, weight: float,
                 dt: float, *, soles_of: SolesOf | None = None) -> Quad:
    """(x, y, vx, vy): the pelvis over its support [m] and its velocity there [m/s].

    legs: (right, left) leg angles [rad] now; before: the same one tick ``dt`` [s] ago
    (None: no motion of the legs); tilt: the torso's (roll, pitch [rad], roll rate, pitch
    rate [rad/s]); weight: the right sole's share of the support (``support_weight``).
    The velocity has two parts: the legs' motion (the change of the position over the
    same support at the same tilt) and the tilt's rate turning the pelvis about the sole
    (omega x c: pitch rate x height forward, -roll rate x height to the left).
    soles_of: ``leg_soles`` of ``g`` (a ``SoleMemo``), by default computed afresh."""
    roll, pitch, roll_rate, pitch_rate = tilt
    fk = soles_of if soles_of is not None else (lambda q: leg_soles(g, q))

    def at(q: Legs) -> Point:
        a, b = over_soles(fk(q), roll, pitch)
        return (weight * a[0] + (1.0 - weight) * b[0], weight * a[1] + (1.0 - weight) * b[1],
                weight * a[2] + (1.0 - weight) * b[2])
    x, y, z = at(legs)
    vx, vy = pitch_rate * z, -roll_rate * z
    if before is not None and dt > 0.0:
        bx, by, _ = at(before)
        vx += (x - bx) / dt
        vy += (y - by) / dt
    return x, y, vx, vy


def unplanned(measured: Quad, planned: Quad, shift: Plane, shift_before: Plane | None,
              dt: float) -> Quad:
    """What the legs' kinematics show that the gait did not plan: ``measured`` (the held
    joints and the torso's tilt) less ``planned`` (the gait's own joints, level, no tilt)
    less ``shift`` [m], the feedback's own step offsets of the support (a foot moved
    forward under the pelvis puts the pelvis that much back over it), and its rate
    [m/s] from ``shift_before`` one tick ``dt`` [s] ago. (x, y [m], vx, vy [m/s])."""
    sx, sy = shift
    bx, by = shift if shift_before is None else shift_before
    rx, ry = ((sx - bx) / dt, (sy - by) / dt) if dt > 0.0 else (0.0, 0.0)
    return (measured[0] - planned[0] - sx, measured[1] - planned[1] - sy,
            measured[2] - planned[2] - rx, measured[3] - planned[3] - ry)
