"""ServoMap: radians ↔ ticks per servo, never a goal outside the tick limits."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robot.bus.servo_map import ServoMap
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.errors import BipedError

# The 18-joint robots (the property tests draw one vector length for all of them; the
# 12-joint robot's map is a subset of the Dynamixel one's).
ROBOTS = {p.stem: r for p in sorted(ROBOTS_DIR.glob("*.toml"))
          if len((r := load_robot(p)).joints) == 18}
MAPS = {name: ServoMap(r) for name, r in ROBOTS.items()}
N = len(next(iter(ROBOTS.values())).joints)
robot_names = st.sampled_from(sorted(ROBOTS))
unit_vectors = st.lists(st.floats(0.0, 1.0), min_size=N, max_size=N).map(np.array)
any_angles = st.lists(st.floats(allow_nan=False), min_size=N, max_size=N)


def in_limits(m: ServoMap, u: np.ndarray) -> np.ndarray:
    return m.q_min + (m.q_max - m.q_min) * u


def tick_range(m: ServoMap) -> tuple[np.ndarray, np.ndarray]:
    """The angles the tick limits stand for (inside the joint limits)."""
    a, b = m.to_rad(m.tick_min), m.to_rad(m.tick_max)
    return np.minimum(a, b), np.maximum(a, b)


@settings(max_examples=150, deadline=None)
@given(robot_names, unit_vectors)
def test_ticks_round_trip_within_half_a_tick(name: str, u: np.ndarray) -> None:
    m = MAPS[name]
    lo, hi = tick_range(m)
    q = lo + (hi - lo) * u
    ticks = m.to_ticks(q)
    assert ticks.dtype == np.int64
    tick = 1.0 / m.ticks_per_rad
    assert np.all(np.abs(m.to_rad(ticks) - q) <= 0.5 * tick + 1e-12)
    # Between a joint limit and the last whole tick inside it: within one tick.
    q = in_limits(m, u)
    assert np.all(np.abs(m.to_rad(m.to_ticks(q)) - q) < tick)
    # The per-tick path (goals) and the vectorised path agree.
    assert m.goals(q.tolist()) == dict(zip(m.ids, m.to_ticks(q).tolist(), strict=True))


@settings(max_examples=100, deadline=None)
@given(robot_names, st.lists(st.integers(0, 4095), min_size=N, max_size=N))
def test_ticks_inside_the_limits_survive_rad_and_back(name: str, raw: list[int]) -> None:
    m = MAPS[name]
    ticks = np.clip(np.array(raw), m.tick_min, m.tick_max)
    q = m.to_rad(ticks)
    assert np.all(q >= m.q_min - 1e-12) and np.all(q <= m.q_max + 1e-12)
    assert np.array_equal(m.to_ticks(q), ticks)
    assert np.array_equal(m.from_positions(dict(zip(m.ids, ticks.tolist(), strict=True))), q)


@settings(max_examples=200, deadline=None)
@given(robot_names, st.one_of(any_angles, st.lists(
    st.sampled_from([math.inf, -math.inf, 1e308, -1e308, 1e20, -1e20, 0.0]),
    min_size=N, max_size=N)))
def test_goals_never_leave_the_tick_limits(name: str, q: list[float]) -> None:
    m = MAPS[name]
    goals = m.goals(q)
    assert list(goals) == list(m.ids)
    ticks = np.array(list(goals.values()))
    assert np.all(ticks >= m.tick_min) and np.all(ticks <= m.tick_max)
    assert all(isinstance(t, int) for t in goals.values())
    assert np.array_equal(m.to_ticks(q), ticks)
    # An angle beyond a joint limit goes to that limit's end, not the other one.
    qa = np.array(q)
    beyond_hi = qa > m.q_max
    at_hi = np.where(m.sign > 0, m.tick_max, m.tick_min)
    assert np.array_equal(ticks[beyond_hi], at_hi[beyond_hi])
    beyond_lo = qa < m.q_min
    at_lo = np.where(m.sign > 0, m.tick_min, m.tick_max)
    assert np.array_equal(ticks[beyond_lo], at_lo[beyond_lo])


def test_tick_limits_stay_inside_the_joint_limits() -> None:
    for m in MAPS.values():
        assert np.all(m.tick_min < m.tick_max)
        lo, hi = tick_range(m)
        assert np.all(lo >= m.q_min - 1e-12) and np.all(hi <= m.q_max + 1e-12)
        assert np.all(lo - m.q_min < 1 / m.ticks_per_rad)     # and lose under one tick
        assert np.all(m.q_max - hi < 1 / m.ticks_per_rad)


def flipped(robot: RobotConfig) -> RobotConfig:
    """The same robot with every servo mounted the other way round, limits mirrored."""
    joints = tuple(dataclasses.replace(j, sign=-j.sign) for j in robot.joints)
    return dataclasses.replace(robot, joints=joints)


@settings(max_examples=100, deadline=None)
@given(robot_names, unit_vectors)
def test_sign_minus_one_maps_mirrored(name: str, u: np.ndarray) -> None:
    robot = ROBOTS[name]
    m, mf = MAPS[name], ServoMap(flipped(robot))
    q = in_limits(m, u)
    t, tf = m.to_ticks(q), mf.to_ticks(q)
    assert np.array_equal(tf - mf.zero, -(t - m.zero))
    assert np.array_equal(mf.tick_min - mf.zero, -(m.tick_max - m.zero))
    assert np.allclose(mf.to_rad(tf), m.to_rad(t), atol=1e-12)


def test_bundled_sign_minus_one_joints_turn_the_other_way() -> None:
    m = MAPS["biped18-dynamixel"]
    for jn in ("l_hip_yaw", "l_hip_roll", "l_ankle_roll"):
        i = m.index(jn)
        assert m.sign[i] == -1
        q = np.zeros(N)
        q[i] = 0.3
        assert m.to_ticks(q)[i] == 2048 - round(0.3 * 4096 / (2 * math.pi))
    i = m.index("r_hip_yaw")
    q = np.zeros(N)
    q[i] = 0.3
    assert m.to_ticks(q)[i] == 2048 + round(0.3 * 4096 / (2 * math.pi))


def test_nan_is_refused_naming_the_joint() -> None:
    m = MAPS["biped18-feetech"]
    q = [0.0] * N
    q[m.index("r_knee")] = math.nan
    with pytest.raises(BipedError, match=r"r_knee \(servo id 4\).*NaN"):
        m.goals(q)
    with pytest.raises(BipedError, match="r_knee"):
        m.to_ticks(q)


def test_helpers() -> None:
    m = MAPS["biped18-dynamixel"]
    v = m.vector({"r_knee": 1.0}, default=0.5)
    assert v[m.index("r_knee")] == 1.0 and np.count_nonzero(v == 0.5) == N - 1
    assert m.named(v)["r_knee"] == 1.0
    assert np.array_equal(m.clamp(np.full(N, 100.0)), m.q_max)
