"""Leg and arm IK: FK(IK(x)) == x on the reachable set, nearest reachable pose outside it
(the arm's singularity and lateral caps: test_arm_ik_singularity.py).

Poses are generated the only way that is sure to be reachable: sample joint angles inside
the limits (away from the straight-knee / straight-elbow singularity), FK them, IK, FK again.
Geometries are random too, so thigh != shin and upper_arm != forearm are covered.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable
from typing import cast

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from robot.config.robot import Geometry
from robot.config.robot_file import load_robot
from robot.gait import xmath as xm
from robot.gait.ik import arm_fk, arm_fk_local, arm_ik, hip_centre, leg_fk, leg_fk_full, leg_ik
from robot.gait.xmath import Rot, Vec

BASE = load_robot().geometry
LEG_LO = np.array([-0.6, -0.5, -1.7, 0.15, -1.2, -0.5])   # knee > 0: away from straight
LEG_HI = np.array([0.6, 0.5, 0.7, 2.3, 1.2, 0.5])
ARM_LO = np.array([-3.0, -1.4, -2.6])                      # elbow < 0: away from straight
ARM_HI = np.array([1.5, 1.4, -0.15])
POS_TOL = 1e-6
ROT_TOL = 1e-6

length = st.floats(0.04, 0.3)
geometry_st = st.builds(lambda th, sh, ah, hw, ua, fa: dataclasses.replace(
    BASE, thigh=th, shin=sh, ankle_height=ah, hip_width=hw, upper_arm=ua, forearm=fa),
    length, length, st.floats(0.0, 0.08), st.floats(0.02, 0.2), length, length)
sides = st.sampled_from(["r", "l"])
unit = st.floats(0.0, 1.0)
unit_vectors = st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(
    lambda v: np.linalg.norm(v) > 0.1).map(lambda v: np.array(v) / np.linalg.norm(v))


def lerp(lo: np.ndarray, hi: np.ndarray, u: np.ndarray) -> np.ndarray:
    return lo + (hi - lo) * u


def vec3(v: Iterable[object]) -> Vec:
    """Three coordinates as the Vec tuple the kinematics take (floats or arrays)."""
    return cast(Vec, tuple(v))


def rot9(v: Iterable[object]) -> Rot:
    return cast(Rot, tuple(v))


def pose_err(a: object, b: object) -> float:
    return float(np.max(np.abs(np.asarray(a, dtype=float) - np.asarray(b, dtype=float))))


def angle_err(a: object, b: object) -> float:
    """Largest joint-angle difference on the circle [rad]: +pi and -pi are one angle (atan2
    on either side of its branch cut, e.g. a signed zero, in a degenerate pose)."""
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    return float(np.max(np.abs((d + np.pi) % (2.0 * np.pi) - np.pi)))


def ankle_of(g: Geometry, sole: object, rot: object) -> np.ndarray:
    """Ankle point: the sole plus the foot's up axis times the ankle height."""
    return np.asarray(sole, dtype=float) + np.asarray(rot, dtype=float).reshape(3, 3)[:, 2] \
        * g.ankle_height


# ------------------------------------------------------------------------------- legs


@settings(max_examples=200, deadline=None)
@given(geometry_st, sides, st.lists(unit, min_size=6, max_size=6))
def test_leg_fk_ik_fk_roundtrip_floats(g: Geometry, side: str, u: list[float]) -> None:
    q = lerp(LEG_LO, LEG_HI, np.array(u))
    sole, rot = leg_fk_full(g, side, tuple(float(v) for v in q))
    sol = leg_ik(g, side, sole, rot)
    assert sol.reachable
    assert all(isinstance(v, float) for v in sol.q)
    sole2, rot2 = leg_fk_full(g, side, sol.q)
    assert pose_err(sole, sole2) < POS_TOL
    assert pose_err(rot, rot2) < ROT_TOL
    # Away from singularities the solution is unique: the same angles come back.
    assert pose_err(q, sol.q) < 1e-6


@settings(max_examples=60, deadline=None)
@given(geometry_st, sides, st.integers(0, 2**32 - 1))
def test_leg_ik_vectorised_equals_scalar(g: Geometry, side: str, seed: int) -> None:
    rng = np.random.default_rng(seed)
    q = lerp(LEG_LO[:, None], LEG_HI[:, None], rng.random((6, 40)))
    sole, rot = leg_fk_full(g, side, tuple(q))
    # Some targets out of reach as well: push every third sole 1 m further down (3x the
    # sole point could still be within reach).
    sole = vec3((sole[0], sole[1], np.where(np.arange(40) % 3 == 0, sole[2] - 1.0, sole[2])))
    vec = leg_ik(g, side, sole, rot)
    assert isinstance(vec.reachable, np.ndarray)
    assert not vec.reachable[::3].any() and vec.reachable[1::3].all()
    sole2, rot2 = leg_fk_full(g, side, vec.q)
    reach = vec.reachable
    assert pose_err(np.array(sole)[:, reach], np.array(sole2)[:, reach]) < POS_TOL
    assert pose_err(np.array(rot), np.array(rot2)) < ROT_TOL
    for i in range(40):
        one = leg_ik(g, side, vec3(float(c[i]) for c in sole),
                     rot9(float(r[i]) for r in rot))
        assert bool(one.reachable) == bool(vec.reachable[i])
        assert pose_err(one.q, [v[i] for v in vec.q]) < 1e-12


@settings(max_examples=150, deadline=None)
@given(geometry_st, sides, unit_vectors, st.floats(1.001, 5.0), st.floats(-0.6, 0.6),
       st.floats(-0.6, 0.6))
def test_leg_too_far_gives_a_straight_leg_pointing_at_the_target(
        g: Geometry, side: str, d: np.ndarray, f: float, yaw: float, pitch: float) -> None:
    reach = g.thigh + g.shin
    rot = xm.rz_ry(yaw, pitch)
    hip = np.array(hip_centre(g, side))
    sole = hip + d * f * reach - np.array(rot).reshape(3, 3)[:, 2] * g.ankle_height
    sol = leg_ik(g, side, vec3(float(v) for v in sole), rot)
    assert not sol.reachable
    assert np.all(np.isfinite(sol.q))
    assert abs(sol.q[3]) < 1e-6                              # knee straight
    sole2, rot2 = leg_fk_full(g, side, sol.q)
    assert pose_err(ankle_of(g, sole2, rot2), hip + d * reach) < POS_TOL
    assert pose_err(rot, rot2) < ROT_TOL                       # the foot keeps its rotation


@settings(max_examples=150, deadline=None)
@given(geometry_st, sides, unit_vectors, st.floats(0.05, 0.98))
def test_leg_too_close_folds_the_knee_towards_the_target(
        g: Geometry, side: str, d: np.ndarray, f: float) -> None:
    gap = abs(g.thigh - g.shin)
    if gap < 0.01:
        g = dataclasses.replace(g, thigh=g.shin + 0.03)
        gap = 0.03
    hip = np.array(hip_centre(g, side))
    sole = hip + d * f * gap - np.array([0.0, 0.0, g.ankle_height])
    sol = leg_ik(g, side, vec3(float(v) for v in sole))
    assert not sol.reachable
    assert np.all(np.isfinite(sol.q))
    sole2, rot2 = leg_fk_full(g, side, sol.q)
    assert pose_err(ankle_of(g, sole2, rot2), hip + d * gap) < POS_TOL


def test_leg_ik_never_nan_on_degenerate_targets() -> None:
    g = BASE
    hip = hip_centre(BASE, "r")
    for sole in [hip, (0.0, 0.0, 0.0), (0.0, -0.045, -g.ankle_height), (1e6, -1e6, 1e6),
                 (0.0, -0.045, -(g.leg_length + g.ankle_height))]:
        sol = leg_ik(g, "r", sole)
        assert np.all(np.isfinite(sol.q)), sole
    arr = leg_ik(g, "l", (np.zeros(3), np.full(3, 0.045), np.array([0.0, -1.0, 1e9])))
    assert np.all(np.isfinite(np.array(arr.q)))


equal_legs = st.floats(0.04, 0.3).map(lambda a: dataclasses.replace(BASE, thigh=a, shin=a))


@settings(max_examples=200, deadline=None)
@given(st.one_of(geometry_st, equal_legs), sides, unit_vectors,
       st.sampled_from(["hip", "folded", "folded_in", "folded_out", "straight", "along_x"]),
       st.floats(-0.5, 0.5), st.floats(-0.5, 0.5))
def test_leg_degenerate_targets_divide_by_nothing(g: Geometry, side: str, e: np.ndarray,
                                                  case: str, yaw: float, pitch: float) -> None:
    """The ankle point at the hip centre, at exactly |thigh - shin| (knee fully bent), just
    inside and outside that, at full reach, and straight along the foot's x axis (ankle
    roll undefined): finite, no numpy warning, and FK exact (1e-12 m) where reachable,
    else the ankle at the clamped distance."""
    a, b = g.thigh, g.shin
    rot = xm.rz_ry(yaw, pitch)
    if case == "along_x":
        e = np.array(rot).reshape(3, 3)[:, 0]
    dist = {"hip": 0.0, "folded": abs(a - b), "folded_in": abs(a - b) - 1e-7,
            "folded_out": abs(a - b) + 1e-7, "straight": a + b, "along_x": 0.5 * (a + b)}[case]
    dist = max(dist, 0.0)
    hip = np.array(hip_centre(g, side))
    ankle = hip + e * dist
    sole = ankle - np.array(rot).reshape(3, 3)[:, 2] * g.ankle_height
    with np.errstate(divide="raise", invalid="raise", over="raise"):
        vec = leg_ik(g, side, vec3(np.array([v, v]) for v in sole),
                     rot9(np.array([v, v]) for v in rot))
    sol = leg_ik(g, side, vec3(float(v) for v in sole), rot)
    assert all(isinstance(v, float) and np.isfinite(v) for v in sol.q)
    assert angle_err(sol.q, [v[0] for v in vec.q]) < 1e-12
    sole2, rot2 = leg_fk_full(g, side, sol.q)
    reach = abs(a - b) - 1e-12 <= dist <= a + b + 1e-12              # ik.REACH_TOL
    assert bool(sol.reachable) == reach
    if reach:
        assert pose_err(ankle_of(g, sole2, rot2), ankle) < 1e-12
        assert pose_err(rot, rot2) < 1e-12
    else:
        assert abs(np.linalg.norm(ankle_of(g, sole2, rot2) - hip) - abs(a - b)) < 1e-12
    if case in ("folded", "hip") and reach:
        assert abs(sol.q[3] - np.pi) < 1e-7                    # knee fully bent


def test_leg_fk_helper_matches_full_fk() -> None:
    q = np.array([0.1, -0.2, -0.5, 1.0, -0.4, 0.1])
    assert pose_err(leg_fk(BASE, "l", q), leg_fk_full(BASE, "l", tuple(q))[0]) == 0.0
    # Zero pose: straight leg under the hip.
    assert pose_err(leg_fk(BASE, "r", np.zeros(6)),
                    (0.0, -BASE.hip_width / 2, -(BASE.leg_length + BASE.ankle_height))) < 1e-15


# ------------------------------------------------------------------------------- arms


@settings(max_examples=200, deadline=None)
@given(geometry_st, st.lists(unit, min_size=3, max_size=3))
def test_arm_fk_ik_fk_roundtrip_floats(g: Geometry, u: list[float]) -> None:
    q = lerp(ARM_LO, ARM_HI, np.array(u))
    hand = arm_fk_local(g, (float(q[0]), float(q[1]), float(q[2])))
    sol = arm_ik(g, hand)
    assert sol.reachable
    assert pose_err(hand, arm_fk_local(g, sol.q)) < POS_TOL
    assert sol.q[2] <= 0.0                                    # elbow bends forward
    assert abs(sol.q[1]) <= np.pi / 2 + 1e-12


@settings(max_examples=60, deadline=None)
@given(geometry_st, st.integers(0, 2**32 - 1))
def test_arm_ik_vectorised_equals_scalar(g: Geometry, seed: int) -> None:
    rng = np.random.default_rng(seed)
    q = lerp(ARM_LO[:, None], ARM_HI[:, None], rng.random((3, 40)))
    hand = arm_fk_local(g, (q[0], q[1], q[2]))
    far = 2.0 * (g.upper_arm + g.forearm) / np.linalg.norm(hand, axis=0)  # out of reach
    hand = vec3(np.where(np.arange(40) % 4 == 0, far * c, c) for c in hand)
    vec = arm_ik(g, hand)
    assert not vec.reachable[::4].any() and vec.reachable[1::4].all()
    reach = vec.reachable
    assert pose_err(np.array(hand)[:, reach], np.array(arm_fk_local(g, vec.q))[:, reach]) \
        < POS_TOL
    for i in range(40):
        one = arm_ik(g, vec3(float(c[i]) for c in hand))
        assert bool(one.reachable) == bool(vec.reachable[i])
        assert pose_err(one.q, [v[i] for v in vec.q]) < 1e-12


@settings(max_examples=150, deadline=None)
@given(geometry_st, unit_vectors, st.one_of(st.floats(1.001, 5.0), st.floats(0.05, 0.98)))
def test_arm_unreachable_goes_to_the_nearest_point_on_the_line(
        g: Geometry, d: np.ndarray, f: float) -> None:
    u, fa = g.upper_arm, g.forearm
    if abs(u - fa) < 0.01:
        g = dataclasses.replace(g, forearm=u + 0.03)
        fa = u + 0.03
    lo, hi = abs(u - fa), u + fa
    dist = f * hi if f > 1 else f * lo
    sol = arm_ik(g, vec3(float(v) for v in d * dist))
    assert not sol.reachable
    assert np.all(np.isfinite(sol.q))
    want = d * (hi if f > 1 else lo)
    assert pose_err(arm_fk_local(g, sol.q), want) < POS_TOL


def test_arm_fk_in_the_pelvis_frame() -> None:
    q = np.array([-0.3, 0.2, -0.8])
    for side, sy in (("r", -1.0), ("l", 1.0)):
        want = np.add(arm_fk_local(BASE, tuple(q)),
                      (0.0, sy * BASE.shoulder_width / 2, BASE.torso_height))
        assert pose_err(arm_fk(BASE, side, q), want) == 0.0
    # Zero pose: the arm hangs straight down.
    assert pose_err(arm_fk_local(BASE, (0.0, 0.0, 0.0)),
                    (0.0, 0.0, -(BASE.upper_arm + BASE.forearm))) < 1e-15
