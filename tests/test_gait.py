"""The paper's channels (robot.gait) against an independent transcription of equations.md.

``EQUATIONS`` below is typed from ../shared/equations.md (eq number, channel name, the
printed expression) and evaluated with ``eval`` on T = t * fps and time = t, in table
order, so each expression may use the channels above it. Nothing from robot.gait is used
to build the expected values.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robot.config.params import SPECS, GaitParams
from robot.gait import expressions as gait

# (eq, channel, expression) exactly as in equations.md, in table order.
EQUATIONS: tuple[tuple[str, str, str], ...] = (
    ("1", "f_pelvis", "sin(T * vM * phi) * omegaB"),
    ("2", "f_spine", "sin(T * vM * k) * omegaC"),
    ("8", "ty", "sin(T * vM) + delta_f"),
    ("9", "tz", "cos(T * vM)"),
    ("3", "StY", "Shgt + tz * omegaB - 0.85"),
    ("4", "StZ", "tz * Sosc - Spos - f_spine - Hpos"),
    ("5", "CtZ", "tz * omegaB - Hpos"),
    ("6", "CtY", "tz * Hosc / 4 + f_pelvis + Hhgt - 0.523"),
    ("7", "StY_ik", "StY + 0.8"),
    ("7", "StZ_ik", "StZ - 0.02"),
    ("10", "Ftau", "sin(T * vM - 70) / 20"),
    ("11", "RightFoot_tY", "ty * Fhgt_R"),
    ("11", "RightFoot_tZ", "-tz * Slgt_R + Fpos_R"),
    ("12", "LeftFoot_tY", "-ty * Fhgt_L"),
    ("12", "LeftFoot_tZ", "-tz * Slgt_L + Fpos_L"),
    ("13", "RightToe_tY", "Ftau"),
    ("13", "LeftToe_tY", "-Ftau"),
    ("14", "RightUpLeg_tZ", "tz * Hosc - Hpos"),
    ("14", "RightUpLeg_tY", "Hhgt + f_pelvis - ty * Hosc"),
    ("15", "LeftUpLeg_tZ", "-tz * Hosc - Hpos"),
    ("15", "LeftUpLeg_tY", "Hhgt + f_pelvis - ty * Hosc"),
    ("16", "Atau_R", "sin(time * 2 * Abnc_R)"),
    ("16", "Atau_L", "sin(time * 2 * Abnc_L)"),
    ("17", "RightArm_tY", "Ahgt_R - Atau_R * Aosc_R"),
    ("17", "RightArm_tZ", "-tz * omega_ra + Apos_R"),
    ("18", "LeftArm_tY", "Ahgt_L - Atau_L * Aosc_L"),
    ("18", "LeftArm_tZ", "tz * omega_la + Apos_L"),
    ("19", "RightShoulder_tY", "-ty * f_spine"),
    ("19", "RightShoulder_tZ", "tz * f_spine"),
    ("20", "LeftShoulder_tY", "ty * f_spine"),
    ("20", "LeftShoulder_tZ", "-tz * f_spine"),
)
CHANNEL_NAMES = tuple(name for _, name, _ in EQUATIONS)
#: The shared reference beside the checkout (../shared, as CI lays it out).
SHARED_EQUATIONS = Path(__file__).resolve().parents[2] / "shared" / "equations.md"
TOL = 1e-12


def printed(t: Any, params: dict[str, float]) -> dict[str, Any]:
    """Every channel of equations.md at time(s) ``t`` [s] (floats or numpy arrays)."""
    is_array = isinstance(t, np.ndarray)
    ns: dict[str, Any] = {"sin": np.sin if is_array else math.sin,
                          "cos": np.cos if is_array else math.cos,
                          "__builtins__": {}}
    ns.update(params)
    ns["T"] = t * params["fps"]
    ns["time"] = t
    out: dict[str, Any] = {}
    for _, name, expr in EQUATIONS:
        ns[name] = out[name] = eval(expr, ns)  # noqa: S307 - our own constant table
    return out


def close(a: Any, b: Any, tol: float = TOL) -> bool:
    return bool(np.all(np.abs(np.asarray(a) - np.asarray(b))
                       <= tol + tol * np.abs(np.asarray(b))))


params_st = st.fixed_dictionaries({
    name: st.floats(spec.lo, spec.hi, allow_nan=False) for name, spec in SPECS.items()})
times_st = st.floats(0.0, 60.0, allow_nan=False)


def test_channel_names_are_the_table_in_order() -> None:
    assert gait.CHANNELS == CHANNEL_NAMES


def test_transcription_matches_the_shared_reference() -> None:
    assert SHARED_EQUATIONS.is_file(), f"{SHARED_EQUATIONS} missing: ../shared must sit beside the repo"
    rows = re.findall(r"^\| (\d+) \| `(\w+)` \| (.+?) \|$", SHARED_EQUATIONS.read_text(),
                      flags=re.M)
    assert tuple(rows) == EQUATIONS


@settings(max_examples=150, deadline=None)
@given(params_st, times_st)
def test_channels_equal_the_printed_formulas(values: dict[str, float], t: float) -> None:
    p = GaitParams(**values)
    got = gait.channels(gait.phase_at(t, p), p)
    want = printed(t, values)
    assert list(got) == list(CHANNEL_NAMES)
    for name in CHANNEL_NAMES:
        assert close(got[name], want[name]), (name, got[name], want[name])


@settings(max_examples=60, deadline=None)
@given(params_st, st.lists(times_st, min_size=1, max_size=40))
def test_vectorised_curves_equal_the_printed_formulas(values: dict[str, float],
                                                      ts: list[float]) -> None:
    p = GaitParams(**values)
    times = np.array(ts)
    got = gait.curves(times, p)
    want = printed(times, values)
    for name in CHANNEL_NAMES:
        assert got[name].shape == times.shape, name
        assert close(got[name], want[name]), name
    # The vectorised path and the per-tick float path agree too.
    for i, t in enumerate(ts):
        one = gait.channels(gait.phase_at(t, p), p)
        assert all(close(got[n][i], one[n]) for n in CHANNEL_NAMES)


def test_constants_are_the_papers() -> None:
    """equations.md: J_error 0.85 (eq 3), 0.523 (eq 6), 0.8 / 0.02 (eq 7), 20 and 70 (eq 10)."""
    assert (gait.J_ERROR_STY, gait.J_ERROR_CTY) == (0.85, 0.523)
    assert (gait.J_ERROR_STY_IK, gait.J_ERROR_STZ_IK) == (0.8, 0.02)
    assert (gait.FTAU_DIVISOR, gait.FTAU_ALPHA) == (20.0, 70.0)


@settings(max_examples=100, deadline=None)
@given(params_st, st.floats(1e-4, 0.02), st.integers(100, 3000))
def test_integrated_phase_equals_phase_at_for_constant_params(
        values: dict[str, float], dt: float, n: int) -> None:
    p = GaitParams(**values)
    ph = gait.Phase(0.0, 0.0, 0.0, 0.0, 0.0)
    for _ in range(n):
        ph = gait.advance(ph, p, dt)
    exact = gait.phase_at(n * dt, p)
    for got, want in zip(ph, exact, strict=True):
        assert math.isclose(got, want, rel_tol=1e-9, abs_tol=1e-9), (got, want)


def test_integrated_phase_does_not_jump_when_vM_changes() -> None:
    """The printed sin(T * vM) jumps when vM changes live; the integrated phase does not."""
    p0 = GaitParams(vM=0.3)
    p1 = GaitParams(vM=0.6)
    dt, t = 0.005, 7.3
    ph = gait.phase_at(t, p0)
    nxt = gait.advance(ph, p1, dt)
    assert nxt.theta - ph.theta == pytest.approx(p1.omega * dt)
    printed_jump = abs(gait.phase_at(t + dt, p1).theta - ph.theta)
    assert printed_jump > 100 * (nxt.theta - ph.theta)


@settings(max_examples=60, deadline=None)
@given(params_st, times_st)
def test_amplitude_one_is_the_default_and_zero_is_static(values: dict[str, float],
                                                         t: float) -> None:
    p = GaitParams(**values)
    ph = gait.phase_at(t, p)
    assert gait.channels(ph, p, amplitude=1.0) == gait.channels(ph, p)
    still = gait.channels(ph, p, amplitude=0.0)
    assert still == gait.channels(gait.Phase(0.0, 0.0, 0.0, 0.0, 0.0), p, amplitude=0.0)
    assert still["ty"] == 0.0 and still["tz"] == 0.0
