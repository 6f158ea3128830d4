"""GaitEngine and the robot mapping: limits, leg alternation, live changes, envelope."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robot.body.legs import fk as leg_chain_fk
from robot.config.bundled import made_for
from robot.config.gait_file import Gait, load_gait
from robot.config.joint_names import LEG_NAMES
from robot.config.params import SPECS, GaitParams
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.gait import expressions as gait
from robot.gait.engine import ENVELOPE_MIN_RATE, GaitEngine, solve
from robot.gait.targets import BodyTargets, BodyTrim, body_targets, scale

RATE = 200.0
DT = 1.0 / RATE
ROBOT = load_robot()
WALKING = ("walk", "crouch", "high_step", "paper")


def cycles(p: GaitParams, n: float) -> np.ndarray:
    return np.arange(0.0, n * p.cycle_s, DT)


def assert_in_limits(robot: RobotConfig, q: np.ndarray, what: str) -> None:
    q = np.asarray(q, dtype=float)
    assert np.all(np.isfinite(q)), what
    for j, row in zip(robot.joints, q, strict=True):
        assert j.min_rad - 1e-12 <= row.min() and row.max() <= j.max_rad + 1e-12, \
            (what, j.name, float(row.min()), float(row.max()))


def targets_of(p: GaitParams, times: np.ndarray, robot: RobotConfig = ROBOT) -> BodyTargets:
    return body_targets(gait.curves(times, p), p, robot.geometry)


# ----------------------------------------------------------------- 3. finite, in limits


def test_preset_curves_are_finite_and_within_limits(any_robot: RobotConfig,
                                                    any_gait: Gait) -> None:
    p = any_gait.for_robot(any_robot)   # the robot's [gait] over the preset, as walk runs it
    times = cycles(p, 3)
    _, q = GaitEngine(any_robot, p).curves(times)
    assert q.shape == (len(any_robot.joints), len(times))
    assert_in_limits(any_robot, q, any_gait.name)
    # The presets are designed inside the limits: the IK itself (before the engine's
    # clamp) stays within them, and every target the robot presets ask for is reachable
    # (on the robots each is made for: robot.config.bundled.NOT_MADE_FOR says why not).
    if not made_for(any_robot.name, any_gait.name):
        return
    raw, ok = solve(targets_of(p, times, any_robot), any_robot)
    assert_in_limits(any_robot, np.array([np.broadcast_to(v, times.shape) for v in raw]),
                     f"{any_gait.name} (raw IK)")
    assert np.all(ok), any_gait.name


def test_preset_ticks_through_start_steady_stop_are_within_limits(
        any_robot: RobotConfig, any_gait: Gait) -> None:
    # The gait's own motion; `climb`'s staircase is off here: its footstep across a riser
    # asks more of the standing leg than it reaches, by design (robot/gait/stair_steps.py,
    # tests/test_climb_plan.py).
    p = any_gait.for_robot(any_robot).replace({"stairs_count": 0.0})
    e = GaitEngine(any_robot, p)
    qs = [e.start_pose()]
    e.start()
    ramp_ticks = math.ceil(p.ramp_cycles * p.cycle_s * RATE)
    for _ in range(ramp_ticks + int(p.cycle_s * RATE) + 1):
        qs.append(e.tick(DT))
    e.stop()
    while not e.stopped:
        qs.append(e.tick(DT))
        assert len(qs) < 4 * ramp_ticks + 2 * p.cycle_s * RATE, "stop never completed"
    assert_in_limits(any_robot, np.array(qs).T, any_gait.name)
    assert e.unreachable_ticks == 0 or not made_for(any_robot.name, any_gait.name)


# ----------------------------------------------------------------- 4. legs alternate


def lifted_runs(lift: np.ndarray) -> list[tuple[int, int]]:
    """[start, end) index ranges where ``lift > 0``, excluding ranges cut by the ends."""
    up = np.concatenate([[False], lift > 0, [False]])
    edges = np.flatnonzero(np.diff(up.astype(int)))
    runs = list(zip(edges[::2], edges[1::2], strict=True))
    return [(a, b) for a, b in runs if a > 0 and b < len(lift)]


@pytest.mark.parametrize("name", WALKING)
def test_each_foot_moves_forward_while_lifted(name: str) -> None:
    p = load_gait(name).params
    times = cycles(p, 3)
    t = targets_of(p, times)
    stride = 2 * scale(ROBOT.geometry, p) * p.speed
    for sole, lift, slgt in ((t.r_sole, t.lift_r, p.Slgt_R), (t.l_sole, t.lift_l, p.Slgt_L)):
        x, lift = np.asarray(sole[0]), np.asarray(lift)
        runs = lifted_runs(lift)
        assert len(runs) >= 2
        for a, b in runs:   # over each swing the foot travels (nearly) a full stride
            assert x[b - 1] - x[a] > 0.8 * stride * slgt, (name, a, b)
    # With the pelvis kept upright and unyawed (no lean, no spine pitch, no hip
    # oscillation) the sole moves forward between any two lifted samples, and back while
    # it alone carries the robot (the other foot lifted).
    flat = p.replace({"torso_lean": 0.0, "spine_gain": 0.0, "Hosc": 0.0})
    t = targets_of(flat, times)
    lr, ll = np.asarray(t.lift_r) > 0, np.asarray(t.lift_l) > 0
    for sole, up, other in ((t.r_sole, lr, ll), (t.l_sole, ll, lr)):
        dx = np.diff(np.asarray(sole[0]))
        assert np.all(dx[up[:-1] & up[1:]] > 0), name
        assert np.all(dx[other[:-1] & other[1:]] < 0), name


params_st = st.fixed_dictionaries({
    n: st.floats(s.lo, s.hi, allow_nan=False) for n, s in SPECS.items()
    if n not in ("delta_f", "speed", "torso_lean", "spine_gain", "Hosc", "turn")})


@settings(max_examples=100, deadline=None)
@given(params_st, st.floats(-1.0, 0.0), st.floats(0.05, 1.5),
       st.lists(st.floats(0.0, 30.0), min_size=2, max_size=30))
def test_feet_never_lifted_together_and_swing_forward(
        values: dict[str, float], delta_f: float, speed: float, ts: list[float]) -> None:
    # Straight walking: turning rotates the feet about the body axis, which bends x.
    p = GaitParams(**values).replace({"delta_f": delta_f, "speed": speed, "torso_lean": 0.0,
                                      "spine_gain": 0.0, "Hosc": 0.0, "turn": 0.0})
    times = np.sort(np.array(ts))
    t = targets_of(p, times)
    lr, ll = np.asarray(t.lift_r), np.asarray(t.lift_l)
    assert np.all(lr >= 0) and np.all(ll >= 0)                       # ground clamp
    assert not np.any((lr > 0) & (ll > 0))
    # Velocity of each sole from a tiny step: forward whenever that foot is lifted.
    t2 = targets_of(p, times + 1e-6)
    for a, b, lift in ((t.r_sole, t2.r_sole, lr), (t.l_sole, t2.l_sole, ll)):
        v = np.asarray(b[0]) - np.asarray(a[0])
        assert np.all(v[lift > 1e-9] > -1e-15)


def test_march_keeps_the_feet_in_place() -> None:
    p = load_gait("march").params
    t = targets_of(p, cycles(p, 3))
    for sole, lift in ((t.r_sole, t.lift_r), (t.l_sole, t.lift_l)):
        # only the preset's ~2 mm backward trim stride (see configs/gaits/march.toml)
        assert np.ptp(np.asarray(sole[0])) < 5e-3
        assert np.max(lift) > 0.01                                     # but they do lift
    assert not np.any((np.asarray(t.lift_r) > 0) & (np.asarray(t.lift_l) > 0))


# ----------------------------------------------------------------- 5. live changes


def run(p: GaitParams, ticks: int, change: Mapping[str, float] | None = None,
        at: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Channels and joint angles per tick at 200 Hz, ``change`` applied before tick ``at``."""
    e = GaitEngine(ROBOT, p)
    e.start()
    chs, qs = [], []
    for i in range(ticks):
        if change and i == at:
            e.set_params(change)
        qs.append(e.tick(DT))
        ch = gait.channels(e.phase, e.live_params, amplitude=e.amplitude)
        chs.append([ch[n] for n in gait.CHANNELS])
    return np.array(chs), np.array(qs)


def max_step(x: np.ndarray) -> np.ndarray:
    return np.abs(np.diff(x, axis=0)).max(axis=0)


@pytest.mark.parametrize("change", [
    {"vM": 0.5},
    {"vM": 0.2},
    {"Slgt_R": 0.9, "Slgt_L": 0.9},
    {"Fhgt_R": 0.7, "Fhgt_L": 0.2},
    {"vM": 0.45, "Slgt_R": 0.2, "Slgt_L": 0.7, "Fhgt_R": 0.6, "Fhgt_L": 0.6},
])
def test_live_changes_do_not_jump(change: dict[str, float]) -> None:
    p = load_gait("walk").params
    steady = math.ceil(p.ramp_cycles * p.cycle_s * RATE) + 20
    n = steady + 3 * int(p.cycle_s * RATE)
    ch_old, q_old = run(p, n)
    ch_new, q_new = run(p.replace(change), n)
    # Typical per-tick motion: one steady cycle of the old and of the new parameters.
    win = slice(steady, steady + int(max(p.cycle_s, p.replace(change).cycle_s) * RATE) + 2)
    typ_ch = np.maximum(max_step(ch_old[win]), max_step(ch_new[win]))
    typ_q = np.maximum(max_step(q_old[win]), max_step(q_new[win]))
    for at in (steady, steady + int(0.3 * p.cycle_s * RATE)):   # mid-stride changes
        ch, q = run(p, n, change, at)
        after = slice(at - 2, n)
        assert np.all(max_step(ch[after]) <= 3 * typ_ch + 1e-9), \
            [gait.CHANNELS[i] for i in np.flatnonzero(max_step(ch[after]) > 3 * typ_ch)]
        assert np.all(max_step(q[after]) <= 3 * typ_q + 1e-9), \
            [ROBOT.joint_names[i] for i in np.flatnonzero(max_step(q[after]) > 3 * typ_q)]
        # Before the change the run is the unchanged one, tick for tick.
        assert np.array_equal(ch[:at], ch_old[:at])


def test_live_change_reaches_the_new_values() -> None:
    p = load_gait("walk").params
    e = GaitEngine(ROBOT, p)
    e.start()
    for _ in range(100):
        e.tick(DT)
    e.set_params({"Slgt_R": 0.9, "vM": 0.4})
    assert e.params.Slgt_R == 0.9 and e.params.vM == 0.4        # what was set, at once
    e.tick(DT)
    assert p.Slgt_R < e.live_params.Slgt_R < 0.9               # followed, not stepped
    for _ in range(int(5 * RATE)):
        e.tick(DT)
    assert e.live_params == e.params


def test_changes_while_stopped_apply_at_once() -> None:
    e = GaitEngine(ROBOT, load_gait("walk").params)
    e.set_params({"Hhgt": -0.3})
    assert e.live_params.Hhgt == -0.3
    assert e.start_pose() == GaitEngine(ROBOT, e.params).start_pose()


# ----------------------------------------------------------------- 6. envelope


def smoothstep(x: float) -> float:
    x = min(max(x, 0.0), 1.0)
    return x * x * (3 - 2 * x)


@pytest.mark.parametrize("name", ["walk", "high_step"])
def test_envelope_ramps_in_and_out_over_ramp_cycles(name: str) -> None:
    p = load_gait(name).params
    ramp_s = p.ramp_cycles * p.cycle_s
    e = GaitEngine(ROBOT, p)
    assert e.amplitude == 0.0 and e.stopped
    e.start()
    amps = []
    for _ in range(math.ceil(ramp_s * RATE) + 5):
        e.tick(DT)
        amps.append(e.amplitude)
    k = np.arange(1, len(amps) + 1) * DT
    assert np.allclose(amps, [smoothstep(x) for x in k / ramp_s], atol=1e-9)
    assert amps[0] > 0.0 and np.all(np.diff(amps) >= 0)
    assert amps[int(ramp_s * RATE) - 2] < 1.0 and amps[-1] == 1.0
    e.stop()
    downs = []
    while not e.stopped:
        e.tick(DT)
        downs.append(e.amplitude)
    assert np.all(np.diff(downs) <= 0) and downs[-1] == 0.0
    assert abs(len(downs) - ramp_s * RATE) <= 2
    # Ramped out: the pose is the start pose again, whatever the phase was.
    assert e.tick(DT) == e.start_pose()
    assert e.amplitude == 0.0


def test_the_envelope_runs_in_gait_time_so_a_braced_stop_holds_its_stride() -> None:
    """The ramp counts cycles of the phase: while the balance loop brakes the phase (a
    brace, tempo -1) the ramp-out holds too, so the stride does not shrink under two
    planted feet (the 5-DoF Dynamixel robot turned 7 deg in such a stop, docs/gait.md),
    at the slowest ENVELOPE_MIN_RATE of its rate so the stop still ends; a phase sped up
    ramps as much faster. By hand: the linear ramp variable x falls by dt / ramp_s x rate
    per tick, and the amplitude is smoothstep(x)."""
    p = load_gait("walk").params
    ramp_s = p.ramp_cycles * p.cycle_s
    e = GaitEngine(ROBOT, p)
    e.start()
    while e.amplitude < 1.0:
        e.tick(DT)
    e.stop()
    x = 1.0
    for tempo, rate, n in ((0.0, 1.0, 40), (-0.5, 0.5, 40), (-0.9, ENVELOPE_MIN_RATE, 40),
                           (-1.0, ENVELOPE_MIN_RATE, 40), (0.1, 1.1, 40)):
        e.trim = BodyTrim(tempo=tempo, land=1.0 if tempo == -1.0 else 0.0)
        theta = e.phase.theta
        for _ in range(n):
            e.tick(DT)
            x -= DT / ramp_s * rate
        assert e.amplitude == pytest.approx(smoothstep(x), abs=1e-9), tempo
        assert (e.phase.theta - theta) % (2 * math.pi) == pytest.approx(
            n * DT * (1 + tempo) * p.omega % (2 * math.pi), abs=1e-9)
    # A stop braced throughout still ends, within 1 / ENVELOPE_MIN_RATE of its time.
    e.trim = BodyTrim(tempo=-1.0, land=1.0)
    ticks = 0
    while not e.stopped:
        e.tick(DT)
        ticks += 1
    assert ticks <= x * ramp_s / ENVELOPE_MIN_RATE / DT + 1
    assert ticks >= x * ramp_s / ENVELOPE_MIN_RATE / DT - 1


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(["walk", "crouch", "high_step", "march", "paper"]),
       st.lists(st.floats(-100, 100), min_size=5, max_size=5))
def test_zero_amplitude_pose_is_the_start_pose(name: str, phase: list[float]) -> None:
    e = GaitEngine(ROBOT, load_gait(name).params)
    start = e.start_pose()
    e.phase = gait.Phase(*phase)
    assert np.allclose(e.pose(amplitude=0.0), start, atol=1e-12, rtol=0)
    assert e.phase == gait.Phase(*phase)                       # start_pose leaves it alone
    assert e.start_pose() == start


def test_start_pose_has_both_feet_flat_on_the_ground(any_robot: RobotConfig,
                                                     any_gait: Gait) -> None:
    p = any_gait.for_robot(any_robot)
    g = any_robot.geometry
    q = dict(zip(any_robot.joint_names, GaitEngine(any_robot, p).start_pose(), strict=True))
    legs = [q.get(name, 0.0) for name in LEG_NAMES]   # 5-DoF legs: no hip yaw, at 0
    # each leg as the IK solves it (an imported robot's offset axes included)
    r_sole, r_rot = leg_chain_fk(any_robot.legs[0], tuple(legs[0:6]))  # type: ignore[arg-type]
    l_sole, l_rot = leg_chain_fk(any_robot.legs[1], tuple(legs[6:12]))  # type: ignore[arg-type]
    # Both feet have the same orientation, and it is the pelvis's inverse (level feet). A
    # leg without ankle roll keeps the sole's heading and pitch (its x axis), not its
    # roll: the Open Duck's soles, set 1 cm inward of where its legs hang ([gait]
    # foot_spread), roll 3 deg (what the IK reports as roll_lost).
    if any_robot.has_ankle_roll:
        assert np.allclose(r_rot, l_rot, atol=1e-9)
    else:
        fwd = np.array(r_rot).reshape(3, 3)[:, 0], np.array(l_rot).reshape(3, 3)[:, 0]
        assert np.allclose(*fwd, atol=1e-9)
    level = np.array(r_rot).reshape(3, 3)       # pelvis → level frame = R_foot^T
    if not any_robot.has_ankle_roll:             # the feet's pitch only (their roll: lost)
        fx = level[:, 0]
        c, s_ = fx[0] / math.hypot(fx[0], fx[2]), -fx[2] / math.hypot(fx[0], fx[2])
        level = np.array([[c, 0.0, s_], [0.0, 1.0, 0.0], [-s_, 0.0, c]])
    r_level = level.T @ np.array(r_sole)
    l_level = level.T @ np.array(l_sole)
    hip_h = p.stance * g.leg_length + g.ankle_height + scale(g, p) * p.Hhgt
    if not made_for(any_robot.name, any_gait.name):   # its stance is out of reach there
        return
    tol = 1e-9 if any_robot.has_ankle_roll else 1e-4   # (the pitch-only frame: ~30 um)
    assert r_level[2] == pytest.approx(-hip_h, abs=tol)
    assert l_level[2] == pytest.approx(-hip_h, abs=tol)
    t = body_targets(gait.channels(gait.Phase(0.0, 0.0, 0.0, 0.0, 0.0), p, amplitude=0.0),
                     p, g, amplitude=0.0)
    assert t.lift_r == 0.0 and t.lift_l == 0.0


def test_steering_follows_a_live_change_at_a_bounded_rate() -> None:
    """A live speed reversal -1 -> +0.3 passes through zero at STEER_RATE, not in one
    first-order step; turn and side_step likewise; other parameters keep PARAM_TAU_S.
    (0.3 / 1.5 + 0.2 / 0.5 + 0.015 / 0.025 = 1.2: inside the steering budget.)"""
    from robot.gait.engine import STEER_RATE

    robot = load_robot("biped18-dynamixel")
    engine = GaitEngine(robot, load_gait("walk").params.replace({"speed": -1.0}))
    engine.start()
    dt = 0.005
    engine.tick(dt)
    engine.set_params({"speed": 0.3, "turn": 0.2, "side_step": 0.015, "sway": 0.03})
    speeds, turns, sides = [], [], []
    for _ in range(200):                                    # 1 s
        engine.tick(dt)
        speeds.append(engine.live_params.speed)
        turns.append(engine.live_params.turn)
        sides.append(engine.live_params.side_step)
    steps = np.diff([-1.0, *speeds])
    assert np.all(steps <= STEER_RATE["speed"] * dt + 1e-12) and np.all(steps > 0)
    assert speeds[-1] == pytest.approx(-1.0 + STEER_RATE["speed"] * 1.0, abs=1e-9)
    assert turns[99] == pytest.approx(STEER_RATE["turn"] * 0.5, abs=1e-9)      # at 0.5 s
    assert sides[99] == pytest.approx(STEER_RATE["side_step"] * 0.5, abs=1e-9)
    assert (turns[-1], sides[-1]) == pytest.approx((0.2, 0.015), abs=1e-12)
    assert engine.live_params.sway == pytest.approx(0.03, abs=1e-6)   # 10 time constants
    for _ in range(700):
        engine.tick(dt)
    assert engine.live_params.speed == 0.3 and engine.live_params.side_step == 0.015
