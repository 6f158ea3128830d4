"""The IK within the knee and elbow limits (robot.gait.ik.leg_reach / arm_reach): a target
the limits put out of reach is met at the nearest distance they allow, along the same
line, with the joint at its limit, not solved beyond the limit and clamped afterwards.

Oracles: the law of cosines by hand for the spans (the issue's figure: an elbow limit of
-2.2 rad keeps the hand 7.8 cm from the shoulder on both 18-joint robots), and the forward
kinematics (ik.arm_fk_local, ik.leg_fk_full: products of rotations, not the IK's closed
form) for where the clamped chain really puts the hand and the foot.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from robot.cli import main
from robot.commands.walk import format_summary
from robot.config.bundled import ROBOTS_DIR
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait import expressions as gait
from robot.gait.engine import GaitEngine
from robot.gait.ik import arm_fk_local, arm_ik, arm_reach, leg_fk_full, leg_ik, leg_reach
from robot.gait.targets import body_targets
from robot.gait.vectorised import solve, spans

DXL = load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")


@pytest.mark.parametrize("name", ["biped18-dynamixel", "biped18-feetech"])
def test_the_elbow_limit_keeps_the_hand_7_8_cm_out(name: str) -> None:
    robot = load_robot(ROBOTS_DIR / f"{name}.toml")
    g = robot.geometry
    r_leg, _, r_arm, _ = spans(robot)
    assert robot.joint("r_elbow").min_rad == -2.2
    u, f = g.upper_arm, g.forearm
    assert r_arm is not None
    assert r_arm.lo == pytest.approx(math.sqrt(u * u + f * f - 2 * u * f * math.cos(math.pi - 2.2)))
    assert r_arm.lo == pytest.approx(0.0776, abs=5e-4)
    assert r_arm.hi == u + f                          # the elbow may straighten (max 0.1)
    a, b = g.thigh, g.shin                            # knee 0 .. 2.3 rad
    assert r_leg.hi == a + b
    assert r_leg.lo == pytest.approx(2 * a * math.cos(2.3 / 2))     # a == b: isosceles


def test_the_geometry_alone_spans_the_whole_annulus() -> None:
    g = DXL.geometry
    assert tuple(arm_reach(g)) == (abs(g.upper_arm - g.forearm), g.upper_arm + g.forearm)
    assert tuple(leg_reach(g)) == (abs(g.thigh - g.shin), g.thigh + g.shin)


@pytest.mark.parametrize("direction", [(0.3, -0.1, -1.0), (1.0, 0.0, 0.2), (-0.5, -0.02, -0.6)])
def test_a_hand_target_inside_the_elbow_limit_is_met_on_its_line(
        direction: tuple[float, float, float]) -> None:
    g = DXL.geometry
    _, _, span, _ = spans(DXL)
    assert span is not None
    unit = np.asarray(direction) / np.linalg.norm(direction)
    target = tuple(0.05 * unit)                       # 5 cm: the elbow would need < -2.2
    free = arm_ik(g, target)
    assert free.q[2] < -2.2 - 0.2 and bool(free.reachable)
    held = arm_ik(g, target, span=span)
    assert not bool(held.reachable)
    assert held.q[2] == pytest.approx(-2.2, abs=1e-12)
    hand = np.asarray(arm_fk_local(g, held.q))
    assert np.linalg.norm(hand) == pytest.approx(span.lo, abs=1e-9)
    assert hand / np.linalg.norm(hand) == pytest.approx(unit, abs=1e-6)
    # The old way (solve freely, clamp the elbow afterwards) lands the hand elsewhere.
    late = np.asarray(arm_fk_local(g, (free.q[0], free.q[1], -2.2)))
    assert np.linalg.norm(late / np.linalg.norm(late) - unit) > 0.05


def test_a_foot_target_inside_the_knee_limit_is_met_on_its_line() -> None:
    g = DXL.geometry
    span, _, _, _ = spans(DXL)
    hip = np.array([0.0, -g.hip_width / 2, 0.0])
    sole = tuple(hip + [0.01, 0.0, -0.06 - g.ankle_height])     # ankle 6.1 cm under the hip
    free = leg_ik(g, "r", sole)
    assert free.q[3] > 2.3 + 0.2
    held = leg_ik(g, "r", sole, span=span)
    assert held.q[3] == pytest.approx(2.3, abs=1e-12)
    pos, rot = leg_fk_full(g, "r", held.q)
    ankle = np.asarray(pos) + g.ankle_height * np.asarray(rot)[[2, 5, 8]]
    want = np.asarray(sole) + [0.0, 0.0, g.ankle_height]
    line = (want - hip) / np.linalg.norm(want - hip)
    assert np.linalg.norm(ankle - hip) == pytest.approx(span.lo, abs=1e-9)
    assert (ankle - hip) / np.linalg.norm(ankle - hip) == pytest.approx(line, abs=1e-9)
    assert np.asarray(rot) == pytest.approx(np.eye(3).ravel(), abs=1e-9)  # foot still level


HIGH_ARMS = {"Ahgt_R": 2.0, "Ahgt_L": 2.0}      # hands raised beyond the shoulders' reach


def test_the_engine_counts_each_joint_held_at_its_limit() -> None:
    """Counted against the general functions' unclamped angles and the limits by hand."""
    params = load_gait("walk").params.replace(HIGH_ARMS)
    engine = GaitEngine(DXL, params)
    engine.start()
    want = [0] * len(DXL.joints)
    for _ in range(400):
        q = engine.tick(0.005)
        ch = gait.channels(engine.phase, engine.live_params, amplitude=engine.amplitude)
        raw, _ = solve(body_targets(ch, engine.live_params, DXL.geometry,
                                    amplitude=engine.amplitude), DXL)
        for i, (v, j) in enumerate(zip(raw, DXL.joints, strict=True)):
            want[i] += not j.min_rad <= float(v) <= j.max_rad
        assert all(j.min_rad <= v <= j.max_rad for v, j in zip(q, DXL.joints, strict=True))
    assert engine.clamp_ticks == want
    held = {DXL.joint_names[i] for i, n in enumerate(want) if n}
    assert held & {"r_shoulder_pitch", "l_shoulder_pitch"}


def test_a_walk_says_which_joints_it_held_at_a_limit(capsys: pytest.CaptureFixture[str]) -> None:
    sets = [a for k, v in HIGH_ARMS.items() for a in ("--set", f"{k}={v}")]
    assert main(["walk", "--json", "--seconds", "2", "--no-balance", *sets]) == 0
    r = json.loads(capsys.readouterr().out)
    ran = r["ticks"] / r["rate_hz"]
    assert set(r["clamped_joints_s"]) & {"r_shoulder_pitch", "l_shoulder_pitch"}
    assert all(0.0 < t <= ran for t in r["clamped_joints_s"].values())
    assert 0.0 < r["ik_unreachable_s"] <= ran
    assert "joint limits  held at a limit: " in format_summary(r)
    assert main(["walk", "--json", "--seconds", "2", "--no-balance"]) == 0
    plain = json.loads(capsys.readouterr().out)
    assert plain["clamped_joints_s"] == {} and plain["ik_unreachable_s"] == 0.0
    assert "joint limits" not in format_summary(plain)
