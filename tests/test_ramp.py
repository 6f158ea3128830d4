"""robot.motion.ramp: invariants, not examples."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robot.errors import ConfigError
from robot.motion.ramp import min_jerk, ramp, ramp_duration, slew_limit

angle = st.floats(-3.0, 3.0, allow_nan=False)
speed = st.floats(0.05, 10.0, allow_nan=False)


@st.composite
def moves(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    n = draw(st.integers(1, 18))
    a = np.array(draw(st.lists(angle, min_size=n, max_size=n)))
    b = np.array(draw(st.lists(angle, min_size=n, max_size=n)))
    v = np.array(draw(st.lists(speed, min_size=n, max_size=n)))
    rate = draw(st.floats(5.0, 500.0))
    return a, b, v, rate


@settings(max_examples=150, deadline=None)
@given(moves(), st.floats(0.0, 1.0))
def test_ramp_invariants(move: tuple, min_duration: float) -> None:  # type: ignore[type-arg]
    a, b, v, rate = move
    path = ramp(a, b, v, rate, min_duration=min_duration)
    assert path.shape[1] == a.size and len(path) >= 2
    assert np.array_equal(path[0], a) and np.array_equal(path[-1], b)
    steps = np.abs(np.diff(path, axis=0))
    assert np.all(steps <= v / rate + 1e-9)
    assert (len(path) - 1) / rate >= min_duration - 1e-9
    # Monotone per joint: never overshoots or backs up.
    d = np.diff(path, axis=0) * np.sign(b - a)
    assert np.all(d >= -1e-12)


def test_ramp_is_smooth_at_both_ends() -> None:
    path = ramp([0.0], [1.0], 1.0, 100.0)
    steps = np.diff(path[:, 0])
    assert steps[0] < 0.01 * steps.max() and steps[-1] < 0.01 * steps.max()
    assert ramp_duration([0.0], [1.0], 1.0) == pytest.approx(1.875)


@settings(max_examples=150, deadline=None)
@given(moves())
def test_slew_limit_never_exceeds_and_reaches(move: tuple) -> None:  # type: ignore[type-arg]
    a, b, v, rate = move
    dt = 1.0 / rate
    q = slew_limit(a, b, v, dt)
    assert np.all(np.abs(q - a) <= v * dt + 1e-12)
    near = np.abs(b - a) <= v * dt
    assert np.array_equal(q[near], b[near])


def test_min_jerk_endpoints() -> None:
    assert min_jerk([0.0, 0.5, 1.0]).tolist() == [0.0, 0.5, 1.0]


@pytest.mark.parametrize("call", [
    lambda: ramp([0.0], [1.0], 0.0, 50.0),
    lambda: ramp([0.0], [1.0], 1.0, -1.0),
    lambda: ramp([0.0, 1.0], [1.0], 1.0, 50.0),
    lambda: ramp([np.nan], [1.0], 1.0, 50.0),
    lambda: slew_limit([0.0], [1.0], 1.0, 0.0),
])
def test_bad_inputs_raise_config_error(call) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ConfigError):
        call()
