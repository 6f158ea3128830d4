"""Capture-point stepping and the brace of the balance law (robot.balance.law), and the
learned gait rhythm (robot.balance.rhythm): signs and sizes computed by hand from the inverted
pendulum (capture point = h * (tilt + tilt rate / sqrt(g / h))), not by the law."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.balance.law import (
    LEARNED,
    Attitude,
    BalanceState,
    GaitPhase,
    balance_step,
)
from robot.balance.rhythm import BINS, Rhythm
from robot.balance.stage import Balance
from robot.balance.stepping import StepState
from robot.config.gait_file import load_gait
from robot.config.params import GaitParams
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.gait.ik import leg_fk_full

DT = 0.005
H = 0.23                       # pendulum length of the test [m]
W0 = math.sqrt(9.81 / H)       # [1/s]
LEVEL = Attitude(roll=0.0, pitch=0.0, roll_rate=0.0, pitch_rate=0.0, yaw_rate=0.0, heading=0.0)
STEP = GaitParams().replace({"bal_step_gain": 1.0, "bal_step_max": 0.08,
                             "bal_step_dead": 0.0, "bal_learn_cycles": 1.0,
                             "bal_ankle_pd": 0.0, "bal_lean_i": 0.0, "bal_heading_p": 0.0,
                             "bal_heading_i": 0.0})
LEARNT = BalanceState(stepping=StepState(rhythm=Rhythm(cycles=LEARNED)), started=True)


def settle(state: BalanceState, tilt: Attitude, p: GaitParams, gait: GaitPhase,
           seconds: float) -> tuple[BalanceState, object]:
    corr = None
    for _ in range(round(seconds / DT)):
        state, corr = balance_step(state, tilt, p, DT, gait)
    return state, corr


# -- the learned rhythm ---------------------------------------------------------------------

def test_the_rhythm_learns_a_periodic_signal_and_leaves_a_disturbance() -> None:
    """A swing 0.9 sin(2 theta) in the pitch rate (the walk's rocking) is learned with the
    default 4-cycle time constant: after 12 time constants the residual is under 1.5 % of
    the swing; a constant 2 rad/s on top shows up in the residual whole."""
    r = Rhythm()
    dtheta = 7.2 * DT                       # the walk preset's phase rate [rad/s] x dt
    theta = 0.0
    for _ in range(round(48 * 2 * math.pi / dtheta)):
        theta += dtheta
        r = r.learn(theta, (0.0, 0.0, 0.0, 0.9 * math.sin(2 * theta)), dtheta, tau_cycles=4.0)
    errs = [abs(r.residual(t, (0.0, 0.0, 0.0, 0.9 * math.sin(2 * t)))[3])
            for t in np.linspace(0, 2 * math.pi, 197)]
    assert max(errs) < 0.015 * 0.9
    pushed = r.residual(1.0, (0.0, 0.0, 0.0, 0.9 * math.sin(2.0) + 2.0))[3]
    assert pushed == pytest.approx(2.0, abs=0.015 * 0.9)
    assert r.cycles == pytest.approx(48.0, rel=1e-3)


def test_the_rhythm_table_wraps_and_interpolates() -> None:
    table = [0.0] * (4 * BINS)
    table[3 * BINS + 0] = 1.0               # pitch rate bin 0 = 1, the others 0
    r = Rhythm(tuple(table))
    assert r.at(0.0)[3] == 1.0
    assert r.at(2 * math.pi)[3] == pytest.approx(1.0)
    assert r.at(0.5 * 2 * math.pi / BINS)[3] == pytest.approx(0.5)   # half way to bin 1
    assert r.at(-0.5 * 2 * math.pi / BINS)[3] == pytest.approx(0.5)  # half way from the last


def test_a_new_walk_is_learned_in_a_cycle_and_a_push_moves_it_little() -> None:
    """A fresh table is a running mean: after one cycle of the swing its residual is under
    1.5 %. Once a bin holds tau cycles of weight, one tick of a 2 rad/s push moves it by
    the tick's share of a pass / tau x the law's clip (0.5 rad/s), not by 2 rad/s."""
    dtheta = 7.2 * DT
    r, theta = Rhythm(), 0.0
    for _ in range(round(2 * math.pi / dtheta)):
        theta += dtheta
        r = r.learn(theta, (0.0, 0.0, 0.0, 0.9 * math.sin(2 * theta)), dtheta, tau_cycles=4.0)
    errs = [abs(r.residual(t, (0.0, 0.0, 0.0, 0.9 * math.sin(2 * t)))[3])
            for t in np.linspace(0, 2 * math.pi, 197)]
    assert max(errs) < 0.015 * 0.9
    learned = Rhythm(weight=(4.0,) * BINS, cycles=10.0)
    state, _ = balance_step(BalanceState(stepping=StepState(rhythm=learned), started=True),
                            LEVEL._replace(pitch_rate=2.0),
                            STEP.replace({"bal_learn_cycles": 4.0}), DT,
                            GaitPhase(theta=0.0, dtheta=dtheta, height=H))
    share = dtheta / (2 * math.pi) * BINS          # of a pass through bin 0
    assert max(state.rhythm.table) == pytest.approx(share / 4.0 * 0.5)


# -- capture-point stepping -------------------------------------------------------------------
# The test's gait: GaitParams' omega = 6 rad/s and delta_f = 0, so the right foot swings
# over theta in (0, pi) and touches down at pi; at theta = pi - 0.6 it lands in 0.1 s.

SWING_R = GaitPhase(theta=math.pi - 0.6, height=H, swinging=(True, False), inward=1.0)
T_LEFT = 0.6 / 6.0                   # [s]


def lip_grow(xi0: float, seconds: float, n: int = 20000) -> float:
    """The capture point's offset from a fixed centre of pressure after ``seconds``:
    xi' = omega0 xi integrated by the midpoint rule (not the law's closed form)."""
    h, xi = seconds / n, xi0
    for _ in range(n):
        xi += h * W0 * (xi + 0.5 * h * W0 * xi)
    return xi


def lip_reach(xi0: float, room: float) -> float:
    """The time [s] until the capture point, from ``xi0``, is ``room`` [m] out (bisection
    on lip_grow)."""
    lo, hi = 0.0, 1.0
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if abs(lip_grow(xi0, mid, 400)) < room else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize(("tilt", "want"), [
    (LEVEL._replace(pitch_rate=0.6), (H * 0.6 / W0, 0.0)),      # tipping forward: step forward
    (LEVEL._replace(pitch_rate=-0.6), (-H * 0.6 / W0, 0.0)),
    (LEVEL._replace(pitch=0.05), (H * 0.05, 0.0)),
    (LEVEL._replace(roll_rate=0.6), (0.0, -H * 0.6 / W0)),      # rolling right: step right
    (LEVEL._replace(roll=-0.04, roll_rate=-0.3), (0.0, H * (0.04 + 0.3 / W0))),
])
def test_the_swinging_foot_lands_where_the_capture_point_will_be(
        tilt: Attitude, want: tuple[float, float]) -> None:
    """The swinging foot lands where the capture point will have drifted to by its
    touchdown (0.1 s away), at the gait's own time when that is within reach."""
    state, corr = settle(LEARNT, tilt, STEP, SWING_R, 1.0)
    rx, ry, lx, ly = corr.feet
    assert corr.capture == pytest.approx(want, abs=1e-12)
    land = (lip_grow(want[0], T_LEFT), lip_grow(want[1], T_LEFT))
    assert max(map(abs, land)) < 0.08                         # inside the reach
    assert (rx, ry) == pytest.approx(land, rel=1e-5, abs=1e-9)
    assert (lx, ly) == (0.0, 0.0)           # the standing foot stays
    assert corr.tempo == 0.0                # the gait's own rhythm


def test_out_of_reach_the_swing_ends_when_the_step_just_fits() -> None:
    """A 3 cm forward error would be 5.8 cm by the gait's touchdown, beyond a 4 cm reach:
    the swing ends when the capture point is 4 cm out (lip_reach), the phase running
    T_LEFT / that time faster, and the foot lands at the reach; with a shorter allowed
    swing than that, the step comes at the shortest swing and is clipped."""
    xi = 0.03
    p = STEP.replace({"bal_step_max": 0.04, "bal_tempo_max": 2.0})
    _, corr = settle(LEARNT, LEVEL._replace(pitch_rate=xi / (H / W0)), p, SWING_R, 1.0)
    t = lip_reach(xi, 0.04)
    assert 0.04 < t < T_LEFT / 2.0          # sooner, yet longer than the shortest swing
    assert corr.tempo == pytest.approx(T_LEFT / t - 1.0, rel=1e-4)
    assert corr.feet[0] == pytest.approx(0.04, rel=1e-6)
    p = p.replace({"bal_tempo_max": 0.5})   # the shortest swing: T_LEFT / 1.5
    _, corr = settle(LEARNT, LEVEL._replace(pitch_rate=xi / (H / W0)), p, SWING_R, 1.0)
    assert corr.tempo == pytest.approx(0.5, rel=1e-6)
    assert corr.feet[0] == pytest.approx(0.04, rel=1e-6)


def test_a_planned_step_is_kept_until_touchdown_and_a_new_swing_plans_afresh() -> None:
    """A 2 cm error plans a step; the error falling back to 0 later in the same swing
    does not withdraw it; the other foot's swing starts from its own plan (0 here)."""
    push = LEVEL._replace(pitch_rate=0.02 / (H / W0))
    state, corr = settle(LEARNT, push, STEP, SWING_R, 0.6)
    planned = lip_grow(0.02, T_LEFT)
    assert corr.feet[0] == pytest.approx(planned, rel=1e-5)
    state, corr = settle(state, LEVEL, STEP, SWING_R, 0.3)
    assert corr.feet[0] == pytest.approx(planned, rel=1e-5)
    swing_l = GaitPhase(theta=2 * math.pi - 0.6, height=H, swinging=(False, True), inward=1.0)
    state, corr = settle(state, LEVEL, STEP, swing_l, 0.3)
    assert corr.feet[0] == pytest.approx(planned, rel=1e-5)   # the right foot stands on it
    assert corr.feet[2:] == (0.0, 0.0)


def test_no_foot_crosses_the_other() -> None:
    """Falling left, the swinging right foot may move left only by ``inward``."""
    gait = GaitPhase(height=H, swinging=(True, False), inward=0.004)
    _, corr = settle(LEARNT, LEVEL._replace(roll_rate=-1.0), STEP, gait, 1.0)
    assert corr.feet[1] == pytest.approx(0.004)
    gait = GaitPhase(height=H, swinging=(False, True), inward=0.004)
    _, corr = settle(LEARNT, LEVEL._replace(roll_rate=1.0), STEP, gait, 1.0)
    assert corr.feet[3] == pytest.approx(-0.004)


def test_steps_are_bounded_and_deadbanded() -> None:
    p = STEP.replace({"bal_step_max": 0.03, "bal_step_dead": 0.01})
    _, corr = settle(LEARNT, LEVEL._replace(pitch_rate=5.0), p, SWING_R, 1.0)
    assert corr.feet[0] == pytest.approx(0.03)
    small = 0.009 / (H / W0)                 # a capture error of 9 mm: inside the band
    _, corr = settle(LEARNT, LEVEL._replace(pitch_rate=small), p, SWING_R, 1.0)
    assert corr.feet[0] == 0.0 and corr.tempo == 0.0
    _, corr = settle(LEARNT, LEVEL._replace(pitch_rate=2 * small), p, SWING_R, 1.0)
    assert corr.feet[0] == pytest.approx(lip_grow(0.018 - 0.01, T_LEFT), rel=1e-5)


def test_nothing_steps_before_the_rhythm_is_learned() -> None:
    gait = GaitPhase(height=H, swinging=(True, False), inward=1.0)
    _, corr = settle(BalanceState(), LEVEL._replace(pitch_rate=1.0), STEP, gait, 0.2)
    assert corr.feet == (0.0, 0.0, 0.0, 0.0) and corr.capture == (0.0, 0.0)


def test_a_forward_step_puts_the_foot_ahead_in_the_leg_fk() -> None:
    """Through the engine and IK: a forward step offset moves the right sole forward
    relative to the pelvis by the offset (leg FK)."""
    robot = load_robot("biped18-dynamixel")
    engine = GaitEngine(robot, load_gait("walk").params)
    q0 = np.array(engine.start_pose())
    from robot.gait.targets import BodyTrim
    engine.trim = BodyTrim(r_dx=0.02)
    q1 = np.array(engine.start_pose())
    names = robot.joint_names
    leg = [names.index(f"r_{j}") for j in ("hip_yaw", "hip_roll", "hip_pitch", "knee",
                                            "ankle_pitch", "ankle_roll")]
    p0, _ = leg_fk_full(robot.geometry, "r", tuple(q0[leg]))
    p1, _ = leg_fk_full(robot.geometry, "r", tuple(q1[leg]))
    assert p1[0] - p0[0] == pytest.approx(0.02, abs=1e-9)
    assert p1[1] == pytest.approx(p0[1], abs=1e-9)


# -- the brace -------------------------------------------------------------------------------

def test_a_large_capture_error_braces_and_calm_releases() -> None:
    """Over bal_brace_xi the gait puts its feet down and holds still (land -> 1, the phase
    rate x (1 + tempo) -> 0); bal_brace_s after the error fell back, it walks again."""
    p = STEP.replace({"bal_step_gain": 0.0, "bal_brace_xi": 0.04, "bal_brace_s": 0.5})
    gait = GaitPhase(height=H, inward=1.0)
    big = 0.05 / (H / W0)
    state, corr = settle(LEARNT, LEVEL._replace(pitch_rate=big), p, gait, 0.15)
    assert corr.land > 0.99 and 1.0 + corr.tempo < 0.01
    state, corr = settle(state, LEVEL, p, gait, 0.45)       # calm, still inside brace_s
    assert corr.land > 0.99
    state, corr = settle(state, LEVEL, p, gait, 0.6)
    assert corr.land < 0.01 and corr.tempo == pytest.approx(0.0, abs=0.01)
    small = 0.03 / (H / W0)
    _, corr = settle(LEARNT, LEVEL._replace(pitch_rate=small), p, gait, 0.3)
    assert corr.land == 0.0


def test_a_forward_error_braces_once_the_swinging_foot_lands() -> None:
    """A forward capture error of 5 cm (over bal_brace_xi = 4 cm) while the right foot
    swings does not put that foot down mid-swing: it lands where the gait puts it, ahead,
    and the base the body tips over is longer. With both feet down it braces. A backward
    or a lateral error of the same size braces at once, mid-swing."""
    p = STEP.replace({"bal_step_gain": 0.0, "bal_brace_xi": 0.04, "bal_brace_s": 0.5})
    big = 0.05 / (H / W0)                    # h x rate / omega0 = 5 cm
    state, corr = settle(LEARNT, LEVEL._replace(pitch_rate=big), p, SWING_R, 0.15)
    assert corr.capture == pytest.approx((0.05, 0.0), rel=1e-9)
    assert corr.land == 0.0 and corr.tempo == 0.0
    _, corr = settle(state, LEVEL._replace(pitch_rate=big), p,
                     GaitPhase(height=H, inward=1.0), 0.15)
    assert corr.land > 0.99 and 1.0 + corr.tempo < 0.01
    for kick, xi in ((LEVEL._replace(pitch_rate=-big), (-0.05, 0.0)),
                     (LEVEL._replace(roll_rate=big), (0.0, -0.05))):
        _, corr = settle(LEARNT, kick, p, SWING_R, 0.15)
        assert corr.capture == pytest.approx(xi, rel=1e-9)
        assert corr.land > 0.99 and 1.0 + corr.tempo < 0.01


def test_braced_the_engine_holds_its_phase_with_both_feet_down() -> None:
    robot = load_robot("biped18-dynamixel")
    params = load_gait("walk").params.replace({"bal_brace_xi": 0.04, "bal_brace_s": 1.0,
                                               "bal_learn_cycles": 0.5, "ramp_cycles": 0.1})
    engine = GaitEngine(robot, params)
    # A sideways kick (a forward one waits for the swinging foot to land).
    tilts = iter([LEVEL] * 400 + [LEVEL._replace(roll_rate=3.0)] * 10 + [LEVEL] * 200)
    stage = Balance(engine, lambda: next(tilts))
    engine.start()
    stage.start()
    for _ in range(410):
        stage(np.asarray(engine.tick(DT)), DT)
    theta = engine.phase.theta
    for _ in range(100):
        stage(np.asarray(engine.tick(DT)), DT)
    assert engine.trim.land > 0.99
    assert engine.phase.theta - theta < 0.01 * params.omega * 100 * DT
    targets_z = _sole_heights(engine)
    assert targets_z[0] == pytest.approx(targets_z[1], abs=1e-3)   # both soles down


def _sole_heights(engine: GaitEngine) -> tuple[float, float]:
    from robot.gait import expressions as gait
    from robot.gait.targets import body_targets
    ch = gait.channels(engine.phase, engine.live_params, amplitude=engine.amplitude)
    t = body_targets(ch, engine.live_params, engine.robot.geometry,
                     amplitude=engine.amplitude, trim=engine.trim)
    return float(t.r_sole[2]), float(t.l_sole[2])


def test_the_gait_holds_rather_than_lift_the_foot_the_body_leans_onto() -> None:
    """Both feet down after the left foot's swing (the right lifts next): leaning right
    (roll rate > 0: capture point to the -y side) past bal_hold_xi holds the phase; leaning
    left does not; once the right foot swings, the left is next and the test reverses."""
    p = STEP.replace({"bal_step_gain": 0.0, "bal_hold_xi": 0.03})
    lean = 0.05 / (H / W0)                       # a 5 cm capture error
    state, _ = settle(LEARNT, LEVEL, p, GaitPhase(height=H, swinging=(False, True)), 0.05)
    assert state.next_lift == 0
    down = GaitPhase(height=H, swinging=(False, False))
    held, corr = settle(state, LEVEL._replace(roll_rate=lean), p, down, 0.2)
    assert 1.0 + corr.tempo < 0.01 and corr.land == 0.0     # still, feet where they are
    _, corr = settle(state, LEVEL._replace(roll_rate=-lean), p, down, 0.2)
    assert corr.tempo == pytest.approx(0.0, abs=1e-9)
    released, corr = settle(held, LEVEL, p, down, 0.6)
    assert corr.tempo == pytest.approx(0.0, abs=0.01)
    state, _ = settle(released, LEVEL, p, GaitPhase(height=H, swinging=(True, False)), 0.05)
    assert state.next_lift == 1
    _, corr = settle(state, LEVEL._replace(roll_rate=-lean), p, down, 0.2)
    assert 1.0 + corr.tempo < 0.01


def test_a_brace_that_holds_too_long_is_given_up_for_a_step() -> None:
    """bal_brace_max_s 0.1 s: a 5 cm backward error (over bal_brace_xi 4 cm) braces at
    once, and after 0.1 s of it the brace is given up (the phase runs again and no hold
    stops it, though the error leans onto the foot that lifts next); the error back under
    4 cm, a new 5 cm error braces again. With bal_brace_max_s 0 the brace holds on."""
    p = STEP.replace({"bal_step_gain": 0.0, "bal_brace_xi": 0.04, "bal_brace_s": 0.3,
                      "bal_brace_max_s": 0.1, "bal_hold_xi": 0.03})
    big = 0.05 / (H / W0)                    # h x rate / omega0 = 5 cm
    back_right = LEVEL._replace(pitch_rate=-big, roll_rate=0.8 * big)   # 4 cm to the right
    down = GaitPhase(height=H, swinging=(False, False))
    state, corr = settle(LEARNT, back_right, p, down, 0.09)
    assert corr.land > 0.95 and not state.stepping.released
    state, corr = settle(state, back_right, p, down, 0.02)
    assert state.stepping.released
    state, corr = settle(state, back_right, p, down, 0.7)     # 7 time constants out
    assert corr.land < 0.01 and corr.tempo == pytest.approx(0.0, abs=0.01)
    state, _ = settle(state, LEVEL, p, down, 0.05)
    assert not state.stepping.released
    _, corr = settle(state, back_right, p, down, 0.05)
    assert corr.land > 0.9
    _, corr = settle(LEARNT, back_right, p.replace({"bal_brace_max_s": 0.0}), down, 0.6)
    assert corr.land > 0.99 and 1.0 + corr.tempo < 0.01
