"""The kinematic capture point (robot.balance.kinematic and its use by the balance law):
where the pelvis stands over its feet from leg angles and the torso's tilt, checked
against forward kinematics worked by hand (planar leg sums of sines and cosines, not the
rotation matrices of robot.gait.ik), and the capture error x + vx / omega0 it feeds the law."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.balance.kinematic import (
    LegSlots,
    body_over_soles,
    leg_angles,
    level,
    over_support,
    support_weight,
    unplanned,
)
from robot.balance.law import LEARNED, Attitude, BalanceState, GaitPhase, balance_step
from robot.balance.rhythm import Rhythm
from robot.balance.stepping import StepState
from robot.config.params import GaitParams
from robot.config.robot_file import load_robot

G = load_robot("biped18-dynamixel").geometry
L = G.thigh + G.shin                    # hip to ankle, leg straight [m]
ZERO = (0.0,) * 6
DT = 0.005


def leg(hip_pitch: float = 0.0, knee: float = 0.0, ankle_pitch: float = 0.0,
        hip_roll: float = 0.0, ankle_roll: float = 0.0) -> tuple[float, ...]:
    return (0.0, hip_roll, hip_pitch, knee, ankle_pitch, ankle_roll)


def test_a_straight_leg_puts_the_pelvis_over_the_sole_by_the_hip_offset() -> None:
    right, left = body_over_soles(G, ZERO, ZERO, 0.0, 0.0)
    assert right == pytest.approx((0.0, G.hip_width / 2, L + G.ankle_height), abs=1e-12)
    assert left == pytest.approx((0.0, -G.hip_width / 2, L + G.ankle_height), abs=1e-12)


def test_a_torso_pitched_forward_puts_the_pelvis_ahead_of_the_sole() -> None:
    """Straight legs, torso (and legs with it) 0.1 rad nose down: the pelvis is (L + ah)
    sin 0.1 ahead of the sole, (L + ah) cos 0.1 above it; 0.1 rad right side down puts it
    to the right (-y) of the right sole by the hip offset's turn."""
    h = L + G.ankle_height
    right, _ = body_over_soles(G, ZERO, ZERO, 0.0, 0.1)
    assert right[0] == pytest.approx(h * math.sin(0.1), abs=1e-12)
    assert right[2] == pytest.approx(h * math.cos(0.1), abs=1e-12)
    right, _ = body_over_soles(G, ZERO, ZERO, 0.1, 0.0)
    # sole in the pelvis frame (0, -w/2, -h), turned about x by 0.1, negated
    w = G.hip_width / 2
    assert right[1] == pytest.approx(-(-w * math.cos(0.1) + h * math.sin(0.1)), abs=1e-12)
    assert right[1] < G.hip_width / 2


def test_a_leg_swung_forward_under_a_torso_pitched_back_stands_the_foot_under_the_pelvis() -> None:
    """Hip pitch 0.3, ankle -0.3 (the foot flat to the pelvis): +hip pitch turns the leg
    back, so the pelvis is L sin 0.3 ahead of the sole. With the torso pitched -0.3 (nose
    up) the shank is vertical in the world and the foot pitched 0.3 back about the ankle:
    the pelvis is ah sin 0.3 behind the sole."""
    q = leg(hip_pitch=0.3, ankle_pitch=-0.3)
    right, _ = body_over_soles(G, q, ZERO, 0.0, 0.0)
    assert right[0] == pytest.approx(L * math.sin(0.3), abs=1e-12)
    assert right[2] == pytest.approx(L * math.cos(0.3) + G.ankle_height, abs=1e-12)
    right, _ = body_over_soles(G, q, ZERO, 0.0, -0.3)
    assert right[0] == pytest.approx(-G.ankle_height * math.sin(0.3), abs=1e-12)
    assert right[2] == pytest.approx(L + G.ankle_height * math.cos(0.3), abs=1e-12)


def test_a_crouched_leg_with_equal_links_stands_the_pelvis_over_the_sole() -> None:
    """Hip -a, knee 2a, ankle -a with thigh = shin: the knee goes forward by thigh sin a and
    the ankle comes back by shin sin a, so the pelvis is right over the sole, (thigh +
    shin) cos a + ah above it."""
    assert G.thigh == G.shin
    a = 0.4
    right, _ = body_over_soles(G, leg(hip_pitch=-a, knee=2 * a, ankle_pitch=-a), ZERO, 0.0, 0.0)
    assert right[0] == pytest.approx(0.0, abs=1e-12)
    assert right[2] == pytest.approx(L * math.cos(a) + G.ankle_height, abs=1e-12)


def test_level_turns_pitch_then_roll() -> None:
    x, y, z = level((0.0, 0.0, -1.0), 0.0, 0.2)
    assert (x, y, z) == pytest.approx((-math.sin(0.2), 0.0, -math.cos(0.2)), abs=1e-15)
    x, y, z = level((0.0, 0.0, -1.0), 0.2, 0.0)
    assert (x, y, z) == pytest.approx((0.0, math.sin(0.2), -math.cos(0.2)), abs=1e-15)


def test_the_support_is_the_standing_sole_or_both() -> None:
    assert support_weight((True, False)) == 1.0
    assert support_weight((False, True)) == 0.0
    assert support_weight((True, True)) == 0.5
    assert support_weight((False, False)) == 0.5


def test_velocity_from_the_legs_and_from_the_tilt_rate() -> None:
    """Standing on the right leg, its hip pitch going 0 -> 0.01 rad in one tick moves the
    pelvis (L + ah) sin 0.01 forward over the sole; a pitch rate of 1 rad/s adds the
    height (L + ah) x 1 m/s; a roll rate of 1 rad/s moves it -(L + ah) m/s (right)."""
    h = L + G.ankle_height
    x, y, vx, vy = over_support(G, (leg(hip_pitch=0.01), ZERO), (ZERO, ZERO),
                                (0.0, 0.0, 0.0, 0.0), 1.0, DT)
    assert x == pytest.approx(h * math.sin(0.01), abs=1e-12)
    assert vx == pytest.approx(h * math.sin(0.01) / DT, rel=1e-9)
    assert y == pytest.approx(G.hip_width / 2) and vy == pytest.approx(0.0, abs=1e-9)
    _, _, vx, vy = over_support(G, (ZERO, ZERO), (ZERO, ZERO), (0.0, 0.0, 1.0, 1.0), 0.5, DT)
    assert vx == pytest.approx(h, abs=1e-12) and vy == pytest.approx(-h, abs=1e-12)


def test_a_step_offset_under_the_support_counts_as_the_body_behind_it() -> None:
    """The pelvis where the gait plans it, over a foot the feedback put 6 cm forward (and
    1 cm left, moving 2 cm in the last tick): the body is 6 cm behind where the walk
    expects it over that foot, 1 cm right, and moving back 4 m/s relative to it."""
    same = (0.01, 0.02, 0.1, 0.0)
    got = unplanned(same, same, (0.06, 0.01), (0.04, 0.01), DT)
    assert got == pytest.approx((-0.06, -0.01, -0.02 / DT, 0.0))
    assert unplanned(same, (0.0, 0.0, 0.0, 0.0), (0.0, 0.0), None, DT) == pytest.approx(same)


def test_leg_slots_leave_out_a_missing_hip_yaw() -> None:
    names = ["r_hip_roll", "r_hip_pitch", "r_knee", "r_ankle_pitch", "r_ankle_roll",
             "l_hip_yaw", "l_hip_roll", "l_hip_pitch", "l_knee", "l_ankle_pitch", "l_ankle_roll"]
    slots = LegSlots.of(names)
    q = [float(i + 1) for i in range(len(names))]
    assert leg_angles(q, slots.right) == (0.0, 1.0, 2.0, 3.0, 4.0, 5.0)
    assert leg_angles(q, slots.left) == (6.0, 7.0, 8.0, 9.0, 10.0, 11.0)


H = 0.23
W0 = math.sqrt(9.81 / H)
LEVEL = Attitude(0.0, 0.0, 0.0, 0.0, 0.0, heading=0.0)
KIN = GaitParams().replace({"bal_step_gain": 1.0, "bal_step_dead": 0.0, "bal_learn_cycles": 1.0,
                            "bal_kin_xi": 1.0})


@pytest.mark.parametrize(("share", "kin", "want"), [
    (1.0, (0.01, 0.0, 0.1, 0.0), (0.01 + 0.1 / W0, 0.0)),     # ahead and moving forward
    (1.0, (0.0, -0.02, 0.0, -0.05), (0.0, -0.02 - 0.05 / W0)),  # to the right, moving right
    (0.5, (0.01, 0.0, 0.1, 0.0), (0.5 * (0.01 + 0.1 / W0), 0.0)),
    (0.0, (0.01, 0.0, 0.1, 0.0), (0.0, 0.0)),                 # off: the tilt alone (level)
])
def test_the_law_takes_the_kinematic_capture_error(share: float, kin: tuple[float, ...],
                                                   want: tuple[float, float]) -> None:
    """With both rhythms learned at zero and a level torso, the capture error the law acts
    on is bal_kin_xi x (x + vx / omega0, y + vy / omega0) of the pelvis's unplanned
    offset over its support."""
    learnt = Rhythm(cycles=LEARNED)
    state = BalanceState(stepping=StepState(rhythm=learnt, kin_rhythm=learnt), started=True)
    p = KIN.replace({"bal_kin_xi": share})
    _, corr = balance_step(state, LEVEL, p, DT, GaitPhase(height=H),
                           (kin[0], kin[1], kin[2], kin[3]))
    assert corr.capture == pytest.approx(want, abs=1e-12)


def test_the_stage_takes_the_legs_at_the_command_plus_the_read_back_lag() -> None:
    """Before anything is sent, this tick's target; then the last command plus the lag
    the read-back showed: taken whole at the first read-back, then followed with the
    50 ms time constant (one 5 ms tick: a tenth of the way), held between read-backs."""
    from robot.balance.stage import LAG_TAU_S, Balance
    from robot.config.gait_file import load_gait
    from robot.gait.engine import GaitEngine

    robot = load_robot("biped18-dynamixel")
    engine = GaitEngine(robot, load_gait("walk").params)
    reads: list[list[float] | None] = []
    stage = Balance(engine, lambda: LEVEL, present=lambda: reads.pop(0) if reads else None)
    n = len(robot.joint_names)
    q = np.full(n, 0.1)
    assert stage.held(q, DT) is q
    stage(q, DT)                                   # sends q (no correction: level, no rate)
    sent = stage._sent
    assert sent is not None
    reads.append((sent - 0.02).tolist())
    assert stage.held(q, DT) == pytest.approx(sent - 0.02)
    assert stage.held(q, DT) == pytest.approx(sent - 0.02)      # no new read: held
    reads.append((sent - 0.04).tolist())
    assert LAG_TAU_S == 0.05
    assert stage.held(q, DT) == pytest.approx(sent - 0.02 - 0.1 * 0.02)
