"""The balance loop's sign conventions and state, checked against forward kinematics
(robot.gait.ik.leg_fk_full) and hand computations, not against the loop itself."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.balance.stage import (
    Attitude,
    Balance,
    BalanceState,
    Correction,
    JointSlots,
    apply,
    balance_step,
    wrap,
)
from robot.config.gait_file import load_gait
from robot.config.params import BALANCE, SPECS, GaitParams
from robot.config.robot_file import load_robot
from robot.gait import xmath as xm
from robot.gait.engine import GaitEngine
from robot.gait.ik import leg_fk_full
from robot.gait.targets import BodyTrim

DT = 0.005
LEVEL = Attitude(roll=0.0, pitch=0.0, roll_rate=0.0, pitch_rate=0.0, yaw_rate=0.0, heading=0.0)
GAINS = GaitParams().replace({"bal_ankle_pd": 0.05, "bal_hip_pd": 0.02, "bal_ankle_pp": 0.1,
                              "bal_lean_i": 1.0, "bal_lean_max": 0.1, "bal_heading_p": 0.5,
                              "bal_heading_i": 0.2, "bal_turn_max": 0.2})


def torso_tilt_over_flat_foot(robot_geometry, side: str, q_leg) -> tuple[float, float]:
    """(roll, pitch) [rad] of the pelvis in the world when the foot of leg angles
    ``q_leg`` (6) lies flat: the inverse of the foot's rotation in the pelvis frame."""
    _, r_foot = leg_fk_full(robot_geometry, side, tuple(q_leg))
    r = xm.transpose(r_foot)         # pelvis in the foot's (world) frame
    pitch = math.asin(-r[6])         # R = Rz Ry Rx: r[6] = -sin(pitch)
    roll = math.atan2(r[7], r[8])
    return roll, pitch


def test_zero_gains_change_nothing() -> None:
    tilt = Attitude(roll=0.1, pitch=-0.2, roll_rate=1.0, pitch_rate=-2.0, yaw_rate=0.5, heading=0.3)
    zero = GaitParams().replace({n: 0.0 for n, spec in SPECS.items() if spec.group == BALANCE})
    _, corr = balance_step(BalanceState(), tilt, zero, DT)
    assert corr._replace(capture=(0.0, 0.0)) == Correction()   # capture: telemetry only


@pytest.mark.parametrize("rate", [0.5, -0.5])
def test_a_forward_tilt_rate_pitches_the_torso_back(rate: float) -> None:
    """Tipping forward (pitch rate > 0, nose down about +y) must raise ankle and hip
    pitch, which over a flat foot pitches the torso back (FK), and vice versa."""
    robot = load_robot("biped18-dynamixel")
    tilt = LEVEL._replace(pitch_rate=rate)
    _, corr = balance_step(BalanceState(), tilt, GAINS, DT)
    q = np.zeros(6)
    q[2], q[3], q[4] = -0.3, 0.6, -0.3   # a crouched stance, foot flat
    before = torso_tilt_over_flat_foot(robot.geometry, "r", q)
    q[2] += corr.hip_pitch
    q[4] += corr.ankle_pitch
    after = torso_tilt_over_flat_foot(robot.geometry, "r", q)
    assert math.copysign(1.0, after[1] - before[1]) == -math.copysign(1.0, rate)
    assert abs(after[0] - before[0]) < 1e-12


@pytest.mark.parametrize("rate", [0.5, -0.5])
def test_a_roll_rate_rolls_the_torso_back(rate: float) -> None:
    robot = load_robot("biped18-dynamixel")
    _, corr = balance_step(BalanceState(), LEVEL._replace(roll_rate=rate), GAINS, DT)
    q = np.zeros(6)
    before = torso_tilt_over_flat_foot(robot.geometry, "l", q)
    q[1] += corr.hip_roll
    q[5] += corr.ankle_roll
    after = torso_tilt_over_flat_foot(robot.geometry, "l", q)
    assert math.copysign(1.0, after[0] - before[0]) == -math.copysign(1.0, rate)


def test_the_lean_is_learned_against_a_steady_tilt_and_bounded() -> None:
    """Leaning back by 0.05 rad (an uphill), the pelvis learns to pitch forward relative
    to the feet at bal_lean_i * 0.05 rad/s, up to bal_lean_max."""
    state = BalanceState()
    tilt = LEVEL._replace(pitch=-0.05, roll=0.02)
    for _ in range(100):                                   # 0.5 s
        state, corr = balance_step(state, tilt, GAINS, DT)
    assert corr.pelvis_pitch == pytest.approx(1.0 * 0.05 * 0.5, rel=1e-9)
    assert corr.pelvis_roll == pytest.approx(-1.0 * 0.02 * 0.5, rel=1e-9)
    for _ in range(2000):                                  # 10 s more
        state, corr = balance_step(state, tilt, GAINS, DT)
    assert corr.pelvis_pitch == pytest.approx(0.1)
    assert corr.pelvis_roll == pytest.approx(-0.1)


def test_the_lean_target_is_the_gaits_own_torso_lean() -> None:
    p = GAINS.replace({"torso_lean": 0.1})
    _, corr = balance_step(BalanceState(), LEVEL._replace(pitch=0.1), p, DT)
    assert corr.pelvis_pitch == 0.0 and corr.ankle_pitch == 0.0


def test_a_heading_to_the_right_of_the_reference_trims_turn_left() -> None:
    """Yawed right by 0.2 rad (heading below the reference): turn + (left), growing over
    a step as the trim follows; the reverse yaw trims right."""
    for yaw, sign in ((-0.2, 1.0), (0.2, -1.0)):
        state, _ = balance_step(BalanceState(), LEVEL, GAINS, DT)   # reference = 0
        turns = []
        for _ in range(200):
            state, corr = balance_step(state, LEVEL._replace(heading=yaw), GAINS, DT)
            turns.append(corr.turn)
        assert all(math.copysign(1.0, t) == sign for t in turns)
        assert abs(turns[-1]) > abs(turns[0])
        assert abs(turns[-1]) <= GAINS.bal_turn_max


def test_without_an_absolute_heading_the_yaw_rate_is_integrated() -> None:
    state = BalanceState()
    tilt = LEVEL._replace(heading=None, yaw_rate=0.4)
    for _ in range(100):
        state, _ = balance_step(state, tilt, GAINS, DT)
    assert state.heading == pytest.approx(0.4 * 100 * DT)


def test_the_reference_follows_the_commanded_turn_rate() -> None:
    """turn [rad/step] at two steps per cycle: after one cycle the reference has turned
    by 2 * turn."""
    p = GAINS.replace({"turn": 0.1})
    state = BalanceState()
    n = round(p.cycle_s / DT)
    for _ in range(n):
        state, _ = balance_step(state, LEVEL, p, p.cycle_s / n)
    assert state.heading_ref == pytest.approx(0.2, rel=1e-9)


def test_wrap() -> None:
    assert wrap(math.pi + 0.1) == pytest.approx(-math.pi + 0.1)
    assert wrap(-math.pi - 0.1) == pytest.approx(math.pi - 0.1)
    assert wrap(0.3) == pytest.approx(0.3)


@pytest.mark.parametrize("name", ["biped18-dynamixel", "biped12-legs"])
def test_corrections_land_on_the_named_joints(name: str) -> None:
    robot = load_robot(name)
    slots = JointSlots.of(robot.joint_names)
    corr = Correction(ankle_pitch=0.1, ankle_roll=0.2, hip_pitch=0.3, hip_roll=0.4)
    out = apply(np.zeros(len(robot.joints)), corr, slots)
    want = {"ankle_pitch": 0.1, "ankle_roll": 0.2, "hip_pitch": 0.3, "hip_roll": 0.4}
    for i, joint in enumerate(robot.joint_names):
        expected = next((v for k, v in want.items() if joint in (f"r_{k}", f"l_{k}")), 0.0)
        assert out[i] == expected, joint


def test_the_stage_trims_the_engine_and_start_forgets() -> None:
    robot = load_robot("biped18-dynamixel")
    engine = GaitEngine(robot, load_gait("walk").params.replace(
        {k: getattr(GAINS, k) for k in ("bal_lean_i", "bal_heading_p", "bal_heading_i")}))
    tilts = iter([LEVEL] + [LEVEL._replace(heading=-0.3, pitch=-0.05)] * 400)
    stage = Balance(engine, lambda: next(tilts))
    stage.start()
    engine.start()
    for _ in range(401):
        stage(engine.tick(DT), DT)
    assert engine.trim.turn > 0.0 and engine.trim.pitch > 0.0
    stage.start()
    assert engine.trim.turn == 0.0 and engine.trim == BodyTrim()
    assert stage.state == BalanceState()
