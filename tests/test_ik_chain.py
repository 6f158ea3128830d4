"""robot.gait.ik_chain: the closed-form IK of real legs inverts robot.body.legs.fk (its
definition, a product of rotation matrices), for every layout it solves, with offsets of
the sizes real robots have; it clamps what it cannot reach without NaN, keeps a 5-DoF
foot's heading and pitch and says which roll it gave up, and refuses what it does not
solve. MuJoCo's FK of hand-written models is the independent oracle:
tests/test_ik_chain_mujoco.py."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robot.body.legs import LegChain, fk
from robot.errors import ConfigError
from robot.gait import xmath as xm
from robot.gait.ik import leg_ik_at, reach
from robot.gait.ik_chain import chain_leg_ik, check_layout, layout_name
from robot.gait.xmath import Rot

TOL = 1e-9      # [m], [rad]
#: layout: (has hip yaw, has ankle roll, order)
LAYOUTS = {"6dof": (True, True, "yaw_roll"), "no_yaw": (False, True, "yaw_roll"),
           "no_roll": (True, False, "yaw_roll"), "no_roll_roll_yaw": (True, False, "roll_yaw")}
#: refused by check_layout (the issue's list), yet the same closed form solves it
LAYOUTS["6dof_roll_yaw"] = (True, True, "roll_yaw")

mm = st.floats(0.0, 1.0, allow_subnormal=False)


@st.composite
def legs(draw: st.DrawFn, layout: str) -> LegChain:
    """A leg with offsets of real robots' sizes: 10-40 mm between the yaw axis and the
    roll-pitch point (or none), roll axis 0-40 mm above the pitch axis, lateral 0-20 mm,
    ankle roll 0-15 mm below the ankle pitch axis, the sole up to 20 mm off the ankle."""
    yaw, roll, order = LAYOUTS[layout]
    side = draw(st.sampled_from("rl"))
    out = -1.0 if side == "r" else 1.0
    u = lambda lo, hi: lo + (hi - lo) * draw(mm)   # noqa: E731
    hip = (u(-0.02, 0.02), out * u(0.03, 0.06), u(-0.03, 0.0))
    yaw_axis = None
    if yaw:
        d, ang = draw(st.sampled_from([0.0, 1.0])) * u(0.01, 0.04), u(-math.pi, math.pi)
        yaw_axis = (hip[0] + d * math.cos(ang), hip[1] + d * math.sin(ang))
    return LegChain(side, hip, u(0.06, 0.12), u(0.06, 0.12),
                    (u(-0.02, 0.02), u(-0.02, 0.02), -u(0.02, 0.04)), yaw_axis=yaw_axis,
                    roll_drop=u(0.0, 0.04), lateral=out * u(0.0, 0.02),
                    ankle_drop=u(0.0, 0.015) if roll else 0.0, has_ankle_roll=roll,
                    order=order)


def angles(leg: LegChain, v: list[float]) -> tuple[float, ...]:
    """Joint angles [rad] from unit draws: the knee 0.05-2 rad, the ankle pitched so the
    hip stays within 0.9 rad of the ankle's up axis (away from the ankle roll's
    singularity, where its two roots meet); 0 for the joints the leg lacks."""
    yaw, roll = leg.has_yaw, leg.has_ankle_roll
    knee = 0.05 + 1.95 * v[3]
    lean = math.atan2(leg.thigh * math.sin(knee), leg.shin + leg.thigh * math.cos(knee))
    return ((v[0] - 0.5) if yaw else 0.0, 0.8 * (v[1] - 0.5), 1.6 * (v[2] - 0.5), knee,
            1.8 * (v[4] - 0.5) - lean, 0.8 * (v[5] - 0.5) if roll else 0.0)


def target(leg: LegChain, q: tuple[float, ...]) -> tuple[tuple[float, ...], Rot]:
    sole, rot = fk(leg, q)  # type: ignore[arg-type]
    return tuple(float(v) for v in sole), tuple(float(v) for v in rot.ravel())  # type: ignore[return-value]


def err(a: object, b: object) -> float:
    return float(np.max(np.abs(np.asarray(a, float) - np.asarray(b, float))))


@pytest.mark.parametrize("layout", LAYOUTS)
@settings(max_examples=150, deadline=None)
@given(data=st.data(), v=st.lists(mm, min_size=6, max_size=6))
def test_the_ik_inverts_the_legs_fk(layout: str, data: st.DataObject, v: list[float]) -> None:
    leg = data.draw(legs(layout))
    q = angles(leg, v)
    sole, rot = target(leg, q)
    sol = chain_leg_ik(leg, sole, rot)  # type: ignore[arg-type]
    assert sol.reachable
    assert all(isinstance(x, float) for x in sol.q)
    assert err(sol.q, q) < TOL                  # the same angles: unique away from the edges
    got_sole, got_rot = fk(leg, sol.q)   # type: ignore[arg-type]
    assert err(got_sole, sole) < TOL
    assert err(got_rot.ravel(), rot) < TOL
    assert abs(sol.roll_lost) < TOL


@pytest.mark.parametrize("order", ["yaw_roll", "roll_yaw"])
@settings(max_examples=150, deadline=None)
@given(data=st.data(), v=st.lists(mm, min_size=6, max_size=6), extra=st.floats(-0.4, 0.4))
def test_a_leg_without_ankle_roll_keeps_heading_and_pitch_and_reports_the_roll(
        order: str, data: st.DataObject, v: list[float], extra: float) -> None:
    """A target rolled about the foot's own x axis beyond what the leg can take: the sole
    point and the foot's x axis (heading, pitch) exactly, and the roll given up is the
    angle between the target's and the achieved sole normal."""
    leg = data.draw(legs("no_roll" if order == "yaw_roll" else "no_roll_roll_yaw"))
    sole, rot = target(leg, angles(leg, v))
    want = np.array(xm.post_rx(rot, extra)).reshape(3, 3)
    sol = chain_leg_ik(leg, sole, tuple(want.ravel()))  # type: ignore[arg-type]
    got_sole, got = fk(leg, sol.q)   # type: ignore[arg-type]
    assert sol.reachable and sol.q[5] == 0.0
    assert err(got_sole, sole) < TOL
    assert err(got[:, 0], want[:, 0]) < TOL                       # heading and pitch
    assert abs(sol.roll_lost - extra) < TOL
    between = math.atan2(float(np.linalg.norm(np.cross(got[:, 2], want[:, 2]))),
                         float(got[:, 2] @ want[:, 2]))
    assert abs(between - abs(extra)) < TOL
    assert err(np.array(xm.post_rx(tuple(got.ravel()), sol.roll_lost)), want.ravel()) < TOL
    level = chain_leg_ik(leg, sole, xm.rot_z(0.3))   # a level target: the sole level in pitch
    assert abs(fk(leg, level.q)[1][2, 0]) < TOL   # type: ignore[arg-type]


@pytest.mark.parametrize("layout", ["6dof", "no_yaw", "no_roll", "no_roll_roll_yaw"])
@settings(max_examples=40, deadline=None)
@given(data=st.data(), seed=st.integers(0, 2**32 - 1))
def test_arrays_give_the_floats_values_and_flag_what_was_clamped(
        layout: str, data: st.DataObject, seed: int) -> None:
    leg = data.draw(legs(layout))
    rng = np.random.default_rng(seed)
    qs = [angles(leg, list(rng.random(6))) for _ in range(30)]
    pts = [target(leg, q) for q in qs]
    soles = np.array([p[0] for p in pts]).T
    soles[2, ::3] -= 1.0                                # every third 1 m too far down
    rots = np.array([p[1] for p in pts]).T
    with np.errstate(divide="raise", invalid="raise", over="raise"):
        vec = chain_leg_ik(leg, tuple(soles), tuple(rots))  # type: ignore[arg-type]
    assert not vec.reachable[::3].any() and vec.reachable[1::3].all()
    for i in range(30):
        one = chain_leg_ik(leg, tuple(soles[:, i]), tuple(rots[:, i]))  # type: ignore[arg-type]
        assert bool(one.reachable) == bool(vec.reachable[i])
        assert err(one.q, [np.asarray(c)[i] for c in vec.q]) < 1e-12


def pitch_point(leg: LegChain, q: tuple[float, ...]) -> np.ndarray:
    """The hip pitch point at angles ``q`` (robot.body.legs.fk of the leg cut there)."""
    cut = dataclasses.replace(leg, thigh=0.0, shin=0.0, lateral=0.0, ankle_drop=0.0,
                              sole=(0.0, 0.0, 0.0))
    return fk(cut, q)[0]   # type: ignore[arg-type]


def ankle_point(leg: LegChain, q: tuple[float, ...]) -> np.ndarray:
    """The ankle pitch point at angles ``q``."""
    return fk(dataclasses.replace(leg, ankle_drop=0.0, sole=(0.0, 0.0, 0.0)), q)[0]  # type: ignore[arg-type]


def pitch_axis(leg: LegChain, q: tuple[float, ...]) -> np.ndarray:
    rot = fk(leg, q)[1]   # type: ignore[arg-type]
    return rot @ np.array([0.0, math.cos(q[5]), -math.sin(q[5])])   # rot Rx(-ankle roll) y


@pytest.mark.parametrize("layout", ["6dof", "no_yaw", "no_roll", "no_roll_roll_yaw"])
@settings(max_examples=100, deadline=None)
@given(data=st.data(), v=st.lists(mm, min_size=6, max_size=6), far=st.booleans(),
       knee=st.one_of(st.just(0.0), st.floats(0.05, 0.6)))
def test_out_of_reach_clamps_along_the_ankle_hip_line_within_the_knee_limits(
        layout: str, data: st.DataObject, v: list[float], far: bool, knee: float) -> None:
    """The target's ankle moved in the pitch plane along the line from the hip pitch
    point, beyond the span the knee limits allow or inside it: finite, not reachable, the
    knee at that end of its limits, the foot's rotation kept, the ankle on that line at
    the end of the span. Within 1e-7 m: a folded leg's ankle near the hip, with the yaw
    axis up to 40 mm beside it, is where the lateral equation's Newton steps converge
    slowest (an ankle at half the span's end missed by 2e-7 m in the fuzz profile)."""
    leg = data.draw(legs(layout))
    q = angles(leg, v)
    hip, n = pitch_point(leg, q), pitch_axis(leg, q)
    line = ankle_point(leg, q) - hip
    line -= (line @ n) * n
    span = reach(leg.thigh, leg.shin, knee, 2.0 + knee)
    to = (1.3 * (leg.thigh + leg.shin) if far else 0.8 * span.lo) / float(np.linalg.norm(line))
    sole, rot = target(leg, q)
    moved = tuple(float(x) for x in np.asarray(sole) + line * (to - 1.0))
    with np.errstate(divide="raise", invalid="raise", over="raise"):
        sol = chain_leg_ik(leg, moved, rot, span=span)  # type: ignore[arg-type]
    assert not sol.reachable and all(math.isfinite(x) for x in sol.q)
    assert abs(sol.q[3] - (knee if far else 2.0 + knee)) < TOL
    assert err(fk(leg, sol.q)[1].ravel(), rot) < 1e-7   # type: ignore[arg-type]
    assert err(pitch_point(leg, sol.q), hip) < 1e-7
    got = ankle_point(leg, sol.q) - hip
    got -= (got @ n) * n
    assert err(got, line / np.linalg.norm(line) * (span.hi if far else span.lo)) < 1e-7


def test_degenerate_targets_give_finite_angles() -> None:
    for yaw, roll, order in LAYOUTS.values():
        leg = LegChain("r", (0.0, -0.04, -0.02), 0.1, 0.1, (0.01, 0.005, -0.03),
                       yaw_axis=(0.016, -0.03) if yaw else None, roll_drop=0.02,
                       lateral=-0.01, ankle_drop=0.01 if roll else 0.0, has_ankle_roll=roll,
                       order=order)
        for sole in [leg.hip, (0.0, 0.0, 0.0), (1e6, -1e6, 1e6), (0.0, -0.05, -0.04),
                     (0.0, -0.05, -0.24)]:
            with np.errstate(divide="raise", invalid="raise", over="raise"):
                arr = chain_leg_ik(leg, tuple(np.array([v, v]) for v in sole))  # type: ignore[arg-type]
            one = chain_leg_ik(leg, sole)
            assert all(math.isfinite(x) for x in one.q), (leg, sole)
            assert err(one.q, [c[0] for c in arr.q]) < 1e-12


def test_a_simple_chain_gives_the_box_models_bits() -> None:
    leg = LegChain("l", (0.0, 0.05, 0.0), 0.1, 0.12, (0.0, 0.0, -0.03), yaw_axis=(0.0, 0.05))
    assert leg.simple
    sole, rot = (0.01, 0.06, -0.2), xm.rz_ry(0.1, 0.2)
    assert chain_leg_ik(leg, sole, rot) == leg_ik_at((0.0, 0.05, 0.0), 0.1, 0.12, 0.03, sole, rot)


@pytest.mark.parametrize(("layout", "refused"), [
    ("6dof", None), ("no_yaw", None), ("no_roll", None), ("no_roll_roll_yaw", None),
    ("6dof_roll_yaw", "6-DoF roll_yaw"), ("4dof", "4-DoF")])
def test_check_layout_refuses_what_the_closed_form_does_not_solve(
        layout: str, refused: str | None) -> None:
    yaw, roll, order = LAYOUTS.get(layout, (False, False, "yaw_roll"))
    leg = LegChain("r", (0.0, -0.04, 0.0), 0.1, 0.1, (0.0, 0.0, -0.03),
                   yaw_axis=(0.02, -0.04) if yaw else None, has_ankle_roll=roll, order=order)
    if refused is None:
        check_layout(leg)
        return
    with pytest.raises(ConfigError, match=refused):
        check_layout(leg, where="model.xml: right leg")
    assert refused in layout_name(leg)
    with pytest.raises(ConfigError, match="order 'yaw_pitch'; valid: yaw_roll, roll_yaw"):
        check_layout(dataclasses.replace(leg, order="yaw_pitch"))
