"""Arm IK at and near its singularities (issue 8, item 7), tested by invariants.

The arm is shoulder pitch (y), roll (x), elbow (y); u = upper arm, f = forearm [m]. Facts
used here, derived by hand (not taken from robot.gait.ik): the hand is Ry(pitch) Rx(roll) h
with h = (-f sin e, 0, -u - f cos e) in the elbow's plane, so |hand| = |h| = d and the
roll can move the hand out of the xz-plane by at most |h_z|. With the law of cosines
that bounds the lateral reach at distance d to |y| <= |d^2 + u^2 - f^2| / (2u), which is
the same as: |p - (0, u sgn y, 0)| >= f (outer lobe) or |p + (0, u sgn y, 0)| <= f (inner
lobe). The workspace is therefore the annulus |f - u| <= d <= u + f minus two lateral
caps, and for f > u the two lobes touch on the singular circle d0 = sqrt(f^2 - u^2),
y = 0. A brute-force search over joint space (independent FK below) confirms it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from test_engine import DT, cycles

from robot.config.gait_file import Gait, load_gait
from robot.config.joint_names import ARM_NAMES
from robot.config.robot import Geometry, RobotConfig
from robot.config.robot_file import load_robot
from robot.gait import expressions as gait
from robot.gait.engine import GaitEngine, solve
from robot.gait.ik import arm_fk_local, arm_ik
from robot.gait.targets import HAND_OUT, body_targets
from robot.gait.vectorised import spans

BASE = load_robot().geometry          # upper_arm 0.08 < forearm 0.09, like both shipped
EXACT = 1e-9                          # FK(IK(x)) == x on the workspace [m]
FOLD_SIN = 1e-6                       # |sin(elbow)| below this: at a fold of the workspace
FOLD_EXACT = 2 * math.sqrt(np.finfo(float).eps)   # there: per metre of arm
SEARCH_TOL = 1e-4                     # accuracy of the brute-force search [m]

geometries = st.builds(lambda u, f: dataclasses.replace(BASE, upper_arm=u, forearm=f),
                       st.floats(0.04, 0.3), st.floats(0.04, 0.3))
angles = st.floats(-math.pi, math.pi)


def with_arm(u: float, f: float) -> Geometry:
    return dataclasses.replace(BASE, upper_arm=u, forearm=f)


def rot_x(a: np.ndarray) -> np.ndarray:
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1),
                     np.stack([z, s, c], -1)], -2)


def rot_y(a: np.ndarray) -> np.ndarray:
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1),
                     np.stack([-s, z, c], -1)], -2)


def hand_of(g: Geometry, pitch: object, roll: object, elbow: object) -> np.ndarray:
    """Independent FK with rotation matrices: hand [m] relative to the shoulder, (..., 3)."""
    pitch, roll, elbow = np.broadcast_arrays(*(np.asarray(v, dtype=float)
                                               for v in (pitch, roll, elbow)))
    fore = rot_y(elbow) @ np.array([0.0, 0.0, -g.forearm])
    return (rot_y(pitch) @ rot_x(roll) @ (fore + [0.0, 0.0, -g.upper_arm])[..., None])[..., 0]


def fk(g: Geometry, q: tuple[object, object, object]) -> np.ndarray:
    return hand_of(g, *q)


def lateral_reach(g: Geometry, d: float) -> float:
    """Largest |y| [m] the hand reaches at distance ``d`` from the shoulder."""
    u, f = g.upper_arm, g.forearm
    return abs(d * d + u * u - f * f) / (2 * u)


def slack(g: Geometry, p: np.ndarray) -> float:
    """> 0 inside the workspace, < 0 outside (a margin in metres, not the distance)."""
    u, f = g.upper_arm, g.forearm
    d = float(np.linalg.norm(p))
    side = np.array([0.0, u * (1.0 if p[1] >= 0 else -1.0), 0.0])
    lobes = max(float(np.linalg.norm(p - side)) - f, f - float(np.linalg.norm(p + side)))
    return min(d - abs(u - f), u + f - d, lobes)


def search_distance(g: Geometry, p: np.ndarray) -> float:
    """Distance [m] from ``p`` to the workspace by brute force over joint space.

    Pitch turns the hand about y, so only roll and elbow are searched and the hand is
    compared in (distance from the y axis, y): a coarse grid, then finer grids around
    the best cells (to within SEARCH_TOL)."""
    rho_t, y_t = math.hypot(p[0], p[2]), p[1]

    def dist(roll: np.ndarray, elbow: np.ndarray) -> np.ndarray:
        h = hand_of(g, 0.0, roll, elbow)
        return np.hypot(np.hypot(h[..., 0], h[..., 2]) - rho_t, h[..., 1] - y_t)

    step = np.pi / 240
    cells = [(r, e) for r in np.arange(-np.pi / 2, np.pi / 2 + step / 2, step)
             for e in np.arange(-np.pi, step / 2, step)]
    best = np.inf
    for keep in (16, 4, 2):
        roll, elbow = np.array(cells).T
        found = dist(roll, elbow)
        best = min(best, float(found.min()))
        grid = np.linspace(-step, step, 21)
        cells = [(min(max(r + dr, -np.pi / 2), np.pi / 2), min(max(e + de, -np.pi), 0.0))
                 for r, e in np.array(cells)[np.argsort(found)[:keep]]
                 for dr in grid for de in grid]
        step /= 10
    return min(best, float(dist(*np.array(cells).T).min()))


def ik_hand(g: Geometry, p: np.ndarray) -> tuple[np.ndarray, bool]:
    sol = arm_ik(g, (float(p[0]), float(p[1]), float(p[2])))
    assert all(isinstance(v, float) and math.isfinite(v) for v in sol.q)
    assert sol.q[2] <= 0.0 and abs(sol.q[1]) <= math.pi / 2          # elbow forward
    # The module's FK and the independent one agree.
    assert np.max(np.abs(np.subtract(arm_fk_local(g, sol.q), fk(g, sol.q)))) < 1e-15
    return fk(g, sol.q), bool(sol.reachable)


def steps(q: np.ndarray, axis: int = -1) -> np.ndarray:
    """Per-step change of angles [rad] along ``axis``; the pitch's wrap at +-pi is no move."""
    return np.abs(np.angle(np.exp(1j * np.diff(q, axis=axis))))


def direction(a: float, b: float) -> np.ndarray:
    """Unit vector from two angles [rad] (azimuth about y, elevation out of the xz-plane)."""
    return np.array([math.cos(b) * math.sin(a), math.sin(b), math.cos(b) * math.cos(a)])


# ------------------------------------------------------------- inside: FK(IK(x)) == x


@settings(max_examples=300, deadline=None)
@given(geometries, angles, st.floats(-math.pi / 2, math.pi / 2), st.floats(-math.pi, 0.0),
       st.sampled_from([None, "roll_edge", "straight", "folded"]))
def test_every_pose_is_reached_again(g: Geometry, pitch: float, roll: float, elbow: float,
                                     edge: str | None) -> None:
    """Targets made by FK over the whole joint range, its edges included."""
    if edge == "roll_edge":
        roll = math.copysign(math.pi / 2, roll)
    elif edge == "straight":
        elbow = 0.0
    elif edge == "folded":
        elbow = -math.pi
    target = fk(g, (pitch, roll, elbow))
    hand, ok = ik_hand(g, target)
    assert ok
    # At a fold of the workspace (arm straight or folded: sin(elbow) ~ 0) the reach-to-
    # elbow map has zero slope, so rounding in the reach moves the elbow by sqrt(eps) and
    # the hand by up to the arm's length times that (hypothesis: elbow -6e-8, 1.3e-9 m).
    fold = abs(math.sin(elbow)) < FOLD_SIN
    assert np.max(np.abs(hand - target)) < (FOLD_EXACT * (g.upper_arm + g.forearm)
                                            if fold else EXACT)


shells = st.sampled_from(["any", "inner_mm", "singular_mm", "singular_circle"])


@settings(max_examples=400, deadline=None)
@given(geometries, shells, st.floats(0.0, 1.0), st.floats(-1.0, 1.0), angles)
def test_targets_sampled_in_the_workspace_are_reached(g: Geometry, shell: str, s: float,
                                                      t: float, azimuth: float) -> None:
    """Targets sampled in space: anywhere, within 1 mm of the inner radius, within 1 mm of
    the singular sphere (where the lateral band is thin) and on the singular circle."""
    u, f = g.upper_arm, g.forearm
    lo, hi = abs(u - f), u + f
    if shell in ("singular_mm", "singular_circle") and f <= u:
        shell = "inner_mm"                                  # no singular sphere: f <= u
    d0 = math.sqrt(max(f * f - u * u, 0.0))
    d = max(lo, {"any": lo + s * (hi - lo), "inner_mm": lo + s * 1e-3,
                 "singular_mm": d0 + (2 * s - 1) * 1e-3, "singular_circle": d0}[shell])
    y = 0.0 if shell == "singular_circle" else t * min(lateral_reach(g, d), d)
    rho = math.sqrt(max(d * d - y * y, 0.0))
    target = np.array([rho * math.sin(azimuth), y, rho * math.cos(azimuth)])
    hand, ok = ik_hand(g, target)
    assert ok
    # At full or least reach the arm is at a fold (straight or folded): sqrt(eps) there
    # (hypothesis: s = 1 - 1e-16 on a 0.165 m arm, 1.7e-9 m).
    fold = min(hi - d, d - lo) < FOLD_SIN * hi
    assert np.max(np.abs(hand - target)) < (FOLD_EXACT * hi if fold else EXACT)


# ------------------------------------------------------------- outside the annulus


@settings(max_examples=300, deadline=None)
@given(geometries, angles, st.floats(-math.pi / 2, math.pi / 2),
       st.one_of(st.floats(1e-6, 0.999), st.floats(1.001, 20.0)))
@example(g=dataclasses.replace(BASE, upper_arm=0.15196224342596729, forearm=0.0625),
         a=0.0, b=math.pi / 2, k=15.5)              # found by a CI draw: straight up, 3.1e-9 m
def test_beyond_the_annulus_the_hand_goes_to_the_nearest_point(
        g: Geometry, a: float, b: float, k: float) -> None:
    """The whole inner and outer sphere is reachable (folded, straight arm), so the nearest
    reachable point is the radial projection onto the annulus, done here by hand."""
    u, f = g.upper_arm, g.forearm
    if abs(u - f) < 0.01:
        g = with_arm(u, u + 0.02)
        f = u + 0.02
    radius = u + f if k > 1 else abs(u - f)
    e = direction(a, b)
    hand, ok = ik_hand(g, e * radius * k)
    assert not ok
    # A straight or fully folded arm is a fold of the workspace: acos near +-1 keeps only
    # sqrt(eps) of the elbow angle (hypothesis found 3.1e-9 m on a 0.21 m arm straight up).
    assert np.max(np.abs(hand - e * radius)) < FOLD_EXACT * (u + f)


@pytest.mark.parametrize("g", [BASE, with_arm(0.09, 0.07), with_arm(0.08, 0.08)],
                         ids=["f>u", "f<u", "f=u"])
def test_the_shoulder_centre_itself(g: Geometry) -> None:
    sol = arm_ik(g, (0.0, 0.0, 0.0))
    assert not sol.reachable or g.upper_arm == g.forearm
    assert sol.q[0] == 0.0 and sol.q[1] == 0.0                  # neutral pitch and roll
    assert abs(np.linalg.norm(fk(g, sol.q)) - abs(g.upper_arm - g.forearm)) < EXACT


@pytest.mark.parametrize("target", [(0.3, 0.1, -0.2), (0.0, 0.0, -0.005), (0.002, -0.001, 0.0),
                                    (0.0, 0.5, 0.0)])
def test_radial_projection_is_the_nearest_by_search(target: tuple[float, float, float]) -> None:
    p = np.array(target)
    hand, ok = ik_hand(BASE, p)
    assert not ok
    assert np.linalg.norm(hand - p) <= search_distance(BASE, p) + SEARCH_TOL


# ------------------------------------------------------------- the lateral caps


@settings(max_examples=300, deadline=None)
@given(geometries, angles, st.floats(0.0, 1.0), st.floats(0.001, 1.0), st.booleans())
def test_out_of_lateral_reach_keeps_distance_and_direction(
        g: Geometry, azimuth: float, s: float, t: float, left: bool) -> None:
    """In the annulus but |y| > lateral reach: the documented clamp, computed by hand:
    same distance, same direction about the pitch axis, |y| = reach^2 / |y_target|."""
    u, f = g.upper_arm, g.forearm
    lo, hi = abs(u - f), u + f
    d = lo + (0.001 + 0.998 * s) * (hi - lo)
    reach = lateral_reach(g, d)
    if reach > d * (1 - 1e-6):
        return                                             # no cap at this distance
    y = (reach + t * (d - reach)) * (1.0 if left else -1.0)
    if abs(y) - reach < 1e-9:
        return
    rho = math.sqrt(max(d * d - y * y, 0.0))
    target = np.array([rho * math.sin(azimuth), y, rho * math.cos(azimuth)])
    hand, ok = ik_hand(g, target)
    assert not ok
    y_hand = math.copysign(reach * reach / abs(y), y)
    rho_hand = math.sqrt(d * d - y_hand * y_hand)
    assert abs(hand[1] - y_hand) < EXACT
    assert abs(math.hypot(hand[0], hand[2]) - rho_hand) < EXACT
    if rho > 0:
        want = np.array([rho_hand * math.sin(azimuth), y_hand, rho_hand * math.cos(azimuth)])
        assert np.max(np.abs(hand - want)) < EXACT
    else:                                     # on the pitch axis: any direction; pitch 0
        assert arm_ik(g, tuple(target)).q[0] == 0.0


CAPS = [(BASE, (0.0, -HAND_OUT, -0.041)), (BASE, (0.0, 0.01, -0.03)),
        (BASE, (0.02, 0.06, -0.01)), (BASE, (0.0, 0.06, 0.0)), (BASE, (0.0, -0.12, 0.04)),
        (with_arm(0.09, 0.07), (0.02, 0.06, -0.01)), (with_arm(0.09, 0.07), (0.0, 0.06, 0.0)),
        (with_arm(0.09, 0.07), (0.0, -0.12, 0.04))]


@pytest.mark.parametrize(("g", "target"), CAPS)
def test_lateral_caps_are_really_out_of_reach(g: Geometry,
                                              target: tuple[float, float, float]) -> None:
    p = np.array(target)
    assert slack(g, p) < 0
    found = search_distance(g, p)
    hand, ok = ik_hand(g, p)
    assert not ok
    assert found > 1e-3                                        # not a rounding matter
    assert np.linalg.norm(hand - p) >= found - SEARCH_TOL     # the search is the best
    assert abs(np.linalg.norm(hand) - np.linalg.norm(p)) < EXACT


def cube(g: Geometry, rng: np.random.Generator, n: int) -> np.ndarray:
    """Random points [m] around the shoulder, a quarter of them near the plane y = 0."""
    r = 1.1 * (g.upper_arm + g.forearm)
    pts = rng.uniform(-r, r, (n, 3))
    pts[: n // 4, 1] *= 0.05
    return pts


@settings(max_examples=100, deadline=None)
@given(geometries, st.integers(0, 2**32 - 1))
def test_reachable_flag_is_the_workspace(g: Geometry, seed: int) -> None:
    """The flag matches the two-lobe description for random points around the shoulder."""
    pts = cube(g, np.random.default_rng(seed), 400)
    margin = np.array([slack(g, p) for p in pts])
    keep = np.abs(margin) > 1e-9
    flags = arm_ik(g, tuple(pts.T)).reachable
    assert np.array_equal(flags[keep], margin[keep] > 0)


@pytest.mark.parametrize("g", [BASE, with_arm(0.09, 0.07)], ids=["f>u", "f<u"])
def test_the_two_lobe_description_agrees_with_search(g: Geometry) -> None:
    pts = cube(g, np.random.default_rng(8), 40)
    margin = np.array([slack(g, p) for p in pts])
    tested = 0
    for p, m in zip(pts, margin, strict=True):
        if abs(m) > 2e-3:
            assert (search_distance(g, p) < SEARCH_TOL) == (m > 0), p
            tested += 1
    assert tested >= 20


# ------------------------------------------------------------- conventions, no 0/0


def test_pitch_axis_and_singular_circle_take_the_neutral_angle() -> None:
    g = BASE
    u, f = g.upper_arm, g.forearm
    d0 = math.sqrt(f * f - u * u)
    for y in (u + f, f - u, -(u + f), -(f - u), 0.05, -0.2):       # poles, cap, outside
        sol = arm_ik(g, (0.0, y, 0.0))
        assert sol.q[0] == 0.0, y                              # pitch undefined: 0
        if abs(y) in (u + f, f - u):
            assert sol.reachable and np.max(np.abs(fk(g, sol.q) - [0, y, 0])) < EXACT
    for az in np.linspace(-np.pi, np.pi, 13):                     # on the singular circle
        p = d0 * direction(float(az), 0.0)
        sol = arm_ik(g, (float(p[0]), float(p[1]), float(p[2])))
        assert sol.reachable and sol.q[1] == 0.0                   # roll undefined: 0
        assert np.max(np.abs(fk(g, sol.q) - p)) < EXACT


def test_no_division_by_zero_at_the_singular_sphere() -> None:
    """Floats raise ZeroDivisionError and numpy warns on 0/0: neither happens, and the
    vectorised result is the float one, for targets packed around the singularities."""
    g = BASE
    u, f = g.upper_arm, g.forearm
    d0 = math.sqrt(f * f - u * u)
    ds = [d0 * (1 + k * 2.0**-52) for k in range(-64, 65)] + [0.0, abs(f - u), u + f]
    pts = [(d * s, y, d * c) for d in ds for y in (0.0, 1e-300, -HAND_OUT)
           for s, c in ((0.0, -1.0), (0.6, 0.8))] + [(0.0, 0.0, 0.0), (0.0, -0.0, -0.0)]
    with np.errstate(divide="raise", invalid="raise", over="raise"):
        vec = arm_ik(g, tuple(np.array(pts).T))
    for i, p in enumerate(pts):
        one = arm_ik(g, p)
        assert all(math.isfinite(v) for v in one.q)
        assert bool(one.reachable) == bool(vec.reachable[i])
        assert np.max(np.abs(np.subtract(one.q, [v[i] for v in vec.q]))) < 1e-12


# ------------------------------------------------------------- continuity


def sweep(g: Geometry, y: float, h: float, x: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Targets (x, y, z) [m] for z from -7.5 to -1.5 cm in steps ``h``: through the singular
    sphere, never across the pitch axis. Returns the targets (n, 3) and angles (3, n)."""
    z = np.arange(-0.075, -0.015, h)
    pts = np.stack([np.full_like(z, x), np.full_like(z, y), z], -1)
    return pts, np.array(arm_ik(g, tuple(pts.T)).q)


@pytest.mark.parametrize("x", [0.0, 0.01, -0.02])
def test_sweep_through_the_singular_circle_moves_as_little_as_the_jacobian_says(
        x: float) -> None:
    """In the plane y = 0 the arm is a planar 2R arm (pitch, elbow; roll 0), reachable
    throughout: per 0.1 mm step the angles move at most h |J^-1| <= h ||J||_F / |det J|
    = h sqrt(d^2 + f^2) / (u f |sin e|) (hand columns of length d and f)."""
    g, h = BASE, 1e-4
    u, f = g.upper_arm, g.forearm
    pts, q = sweep(g, 0.0, h, x)
    assert np.all(arm_ik(g, tuple(pts.T)).reachable)
    assert np.max(np.abs(fk(g, tuple(q)) - pts)) < EXACT
    assert np.all(q[1] == 0.0)
    d = np.linalg.norm(pts, axis=1)
    cos_e = (d * d - u * u - f * f) / (2 * u * f)
    bound = h * np.sqrt(d * d + f * f) / (u * f * np.sqrt(1 - cos_e**2))
    assert np.all(steps(q).max(axis=0) <= 1.05 * np.maximum(bound[1:], bound[:-1]))


@pytest.mark.parametrize("y", [HAND_OUT, -HAND_OUT, 1e-3, -5e-3, 0.03])
def test_sweep_across_the_singular_sphere_out_of_plane_does_not_flip(y: float) -> None:
    """Off the plane the sweep leaves the workspace (the band |y| <= reach closes at d0):
    the roll must swing from one edge to the other without a jump. Continuity: the
    largest per-step change stays small and shrinks with the step (a flip would not);
    at the edges of reach it shrinks like sqrt(step), as at any fold of a workspace."""
    g = BASE
    pts, q = sweep(g, y, 1e-4)
    flags = arm_ik(g, tuple(pts.T)).reachable
    assert flags.any() and not flags.all()
    assert np.array_equal(flags, [slack(g, p) > 0 for p in pts])
    assert np.max(np.abs(fk(g, tuple(q[:, flags])) - pts[flags])) < EXACT
    coarse = steps(q).max()
    fine = steps(sweep(g, y, 1e-6)[1]).max()
    assert coarse < 0.25                        # rad per 0.1 mm; the old IK flipped by pi
    assert fine < coarse / 8


def test_raising_the_hands_through_the_singularity_is_smooth(armed_robot: RobotConfig) -> None:
    """The issue's case: wrist height Ahgt raised in small steps brings the hands to ~4 cm
    from the shoulders. The arm joints move smoothly, the flag turns False exactly where
    |y| = HAND_OUT exceeds the lateral reach, and FK(IK) is exact while reachable and
    no nearer than the elbow limit lets the hand come (vectorised.spans); nearer, the
    elbow stays at its limit."""
    robot = armed_robot
    g = robot.geometry
    near = spans(robot)[2]
    assert near is not None
    base = load_gait("walk").params
    prev: np.ndarray | None = None
    seen = set()
    for ahgt in np.arange(1.5, 3.0, 0.002):
        p = base.replace({"Ahgt_R": float(ahgt), "Ahgt_L": float(ahgt)})
        t = body_targets(gait.channels(gait.Phase(0.0, 0.0, 0.0, 0.0, 0.0), p), p, g)
        q, _ = solve(t, robot)
        by_name = dict(zip(robot.joint_names, q, strict=True))
        arms = np.array([by_name[n] for n in ARM_NAMES], dtype=float)
        for hand, qa in ((t.r_hand, arms[:3]), (t.l_hand, arms[3:])):
            target = np.array(hand, dtype=float)
            ok = bool(arm_ik(g, hand).reachable)
            assert ok == (slack(g, target) > 0)
            seen.add(ok)
            if ok and np.linalg.norm(target) >= near.lo:
                assert np.max(np.abs(fk(g, tuple(qa)) - target)) < EXACT
            elif ok:
                assert qa[2] == pytest.approx(robot.joint("r_elbow").min_rad, abs=1e-12)
        if prev is not None:
            assert steps(np.stack([prev, arms]), axis=0).max() < 0.2, ahgt
        prev = arms
    assert seen == {True, False}


def test_presets_keep_the_arms_reachable_and_within_servo_speed(
        armed_robot: RobotConfig, any_gait: Gait) -> None:
    """Every preset on both robots, ticked through start, two cycles and stop: every arm
    target is reachable and the arm joints never move faster than their servos."""
    # `climb`'s staircase off: the arms' motion is the gait's (tests/test_climb_plan.py).
    p, g = any_gait.params.replace({"stairs_count": 0.0}), armed_robot.geometry
    t = body_targets(gait.curves(cycles(p, 3), p), p, g)
    for hand in (t.r_hand, t.l_hand):
        assert np.all(arm_ik(g, hand).reachable)
    e = GaitEngine(armed_robot, p)
    qs = [e.start_pose()]
    e.start()
    for _ in range(round((p.ramp_cycles + 2) * p.cycle_s / DT)):
        qs.append(e.tick(DT))
    e.stop()
    while not e.stopped:
        qs.append(e.tick(DT))
    assert e.unreachable_ticks == 0
    arm = np.array(qs)[:, 12:]
    speed = np.array([j.max_speed_rad_s for j in armed_robot.joints[12:]])
    assert np.all(steps(arm, axis=0).max(axis=0) <= speed * DT)
