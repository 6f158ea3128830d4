"""Heading on 5-DoF legs (no hip yaw): ``turn`` steers by step length, and a walk says when
its heading drifts unasked.

The oracle of the stride law is a differential drive written out by hand: feet
``hip_width / 2 + foot_spread`` either side of the pelvis, each stride shifted by ``turn`` x
that half gap in step with the stride (right forward, left back for a left turn), capped
at half the stride amplitude.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from five_dof import five_dof_robot, five_dof_with_head

from robot.cli import main
from robot.config.gait_file import load_gait
from robot.config.params import GaitParams
from robot.gait import expressions as gait
from robot.gait.engine import GaitEngine
from robot.gait.ik import leg_fk_full
from robot.gait.targets import NO_TRIM, TURN_RANGE, BodyTrim, body_targets
from robot.run.walk import HEADING_DRIFT_DEG_MIN

ROBOT = five_dof_robot()
#: The walk, with the pelvis kept level (no lean, no spine pitch), so sole targets in the
#: pelvis frame are the level frame's.
LEVEL = load_gait("walk").params.replace({"torso_lean": 0.0, "spine_gain": 0.0})


def soles(p: GaitParams, theta: float, trim: BodyTrim = NO_TRIM) -> tuple[float, float]:
    """Right and left sole x [m] at phase ``theta``, full amplitude."""
    ph = gait.Phase(theta, 0.0, 0.0, 0.0, 0.0)
    t = body_targets(gait.channels(ph, p), p, ROBOT.geometry, leg_yaw=False, trim=trim)
    return float(t.r_sole[0]), float(t.l_sole[0])


@pytest.mark.parametrize("turn", [0.1, -0.1, 0.03])
def test_a_left_turn_lengthens_the_right_stride_by_the_half_gap(turn: float) -> None:
    g = ROBOT.geometry
    half_gap = g.hip_width / 2 + LEVEL.foot_spread
    s = g.leg_length / LEVEL.rig_leg
    assert turn * half_gap < 0.5 * s * LEVEL.Slgt_R            # inside the cap
    straight, turning = LEVEL, LEVEL.replace({"turn": turn})
    for theta in (0.0, 0.7, math.pi / 2, 2.0, math.pi, 4.0):
        r0, l0 = soles(straight, theta)
        r1, l1 = soles(turning, theta)
        shift = -math.cos(theta) * turn * half_gap             # both feet, by hand
        assert r1 - r0 == pytest.approx(shift, abs=1e-12)
        assert l1 - l0 == pytest.approx(shift, abs=1e-12)
    # Stride lengths (front to back over a cycle): right + 2 turn half_gap, left - that.
    r_len = soles(turning, math.pi)[0] - soles(turning, 0.0)[0]
    l_len = soles(turning, 0.0)[1] - soles(turning, math.pi)[1]
    r_ref = soles(straight, math.pi)[0] - soles(straight, 0.0)[0]
    assert r_len - r_ref == pytest.approx(2 * turn * half_gap, abs=1e-12)
    assert l_len - r_ref == pytest.approx(-2 * turn * half_gap, abs=1e-12)


@pytest.mark.parametrize("gain", [1.0, -0.5, 0.0, 2.0])
def test_the_heading_trim_steers_by_step_length_times_bal_stride_turn(gain: float) -> None:
    """A heading loop's turn trim (BodyTrim.turn) moves the soles as an asked turn of
    turn + bal_stride_turn x trim would (kept inside the turn range): the same stride
    shift by hand, -cos(theta) x turn x half gap on both feet; 0 leaves it out."""
    half_gap = ROBOT.geometry.hip_width / 2 + LEVEL.foot_spread
    p = LEVEL.replace({"turn": 0.02, "bal_stride_turn": gain})
    trim = BodyTrim(turn=0.04)
    turn = min(max(0.02 + gain * 0.04, TURN_RANGE[0]), TURN_RANGE[1])
    for theta in (0.0, 0.7, math.pi / 2, 2.0, math.pi, 4.0):
        r0, l0 = soles(p.replace({"turn": 0.0}), theta)
        r1, l1 = soles(p, theta, trim)
        shift = -math.cos(theta) * turn * half_gap
        assert r1 - r0 == pytest.approx(shift, abs=1e-12)
        assert l1 - l0 == pytest.approx(shift, abs=1e-12)


def test_the_stride_shift_is_capped_at_half_the_stride() -> None:
    s = ROBOT.geometry.leg_length / LEVEL.rig_leg
    short = LEVEL.replace({"Slgt_R": 0.05, "Slgt_L": 0.05, "turn": 0.5})
    r0, _ = soles(short.replace({"turn": 0.0}), 0.0)
    r1, _ = soles(short, 0.0)
    assert r1 - r0 == pytest.approx(-0.5 * s * 0.05, abs=1e-12)


def test_the_engine_counts_the_heading_its_turn_asks_for() -> None:
    """Once ramped in, ``turn`` per step, two steps per cycle (``cycle_s``)."""
    p = load_gait("walk").params.replace({"turn": 0.1})
    engine = GaitEngine(ROBOT, p)
    engine.start()
    while engine.amplitude < 1.0:
        engine.tick(0.005)
    before = engine.asked_yaw
    for _ in range(2000):                                      # 10 s
        engine.tick(0.005)
    assert engine.asked_yaw - before == pytest.approx(0.1 * 2 * 10.0 / p.cycle_s, rel=1e-9)


def walk(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, Any]:
    assert main(["walk", "--json", "--seconds", "10", *args]) == 0
    out: dict[str, Any] = json.loads(capsys.readouterr().out)
    return out


def test_an_open_loop_five_dof_walk_is_flagged_when_it_drifts(
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """Open loop the 5-DoF robot yaws tens of degrees a minute (about -60 measured); the
    balance loop holds the bundled robot within a few."""
    r = walk(capsys, "--robot", str(five_dof_with_head(tmp_path)), "--no-balance")
    assert r["heading_asked_deg"] == 0.0
    minutes = r["ticks"] / r["rate_hz"] / 60.0
    assert r["heading_drift_deg_min"] == pytest.approx(r["heading_change_deg"] / minutes)
    assert r["heading_drifts"] is (abs(r["heading_drift_deg_min"]) > HEADING_DRIFT_DEG_MIN)
    assert r["heading_drifts"] is True
    held = walk(capsys)
    assert held["heading_drifts"] is False


def test_the_heading_loop_holds_a_five_dof_robot_by_step_length_with_its_own_sign(
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """In MuJoCo (balance on, 20 s) this robot turns left for `--set turn=0.05` (+22 deg
    measured), so bal_stride_turn = 1 is its sign: the loop holds it (+1.2 deg measured,
    lateral 1 cm). The opposite sign ran away (+16 deg) before the loop checked its own
    sign (robot.balance.heading_sign, issue 32): it now flips it and holds (-0.3 deg)."""
    robot = str(five_dof_with_head(tmp_path))

    def heading(gain: float) -> float:
        assert main(["walk", "--json", "--seconds", "20", "--robot", robot,
                     "--set", f"bal_stride_turn={gain:g}"]) == 0
        r = json.loads(capsys.readouterr().out)
        assert r["fell"] is False
        return float(r["heading_change_deg"])
    held, flipped = heading(1.0), heading(-1.0)
    assert abs(held) < 5.0
    assert abs(flipped) < 5.0


def test_an_asked_turn_is_not_drift(capsys: pytest.CaptureFixture[str]) -> None:
    r = walk(capsys, "--set", "turn=0.1")
    assert r["heading_asked_deg"] > 30.0
    minutes = r["ticks"] / r["rate_hz"] / 60.0
    assert r["heading_drift_deg_min"] == pytest.approx(
        (r["heading_change_deg"] - r["heading_asked_deg"]) / minutes)


def test_a_live_turn_lengthens_the_right_stride_of_a_five_dof_robot() -> None:
    """What the panel's turn slider does (GaitEngine.set_params while walking): the right
    sole's fore-aft travel, from the joint angles through the forward kinematics, grows by
    2 x turn x the half gap."""
    def right_travel(turn: float) -> float:
        engine = GaitEngine(ROBOT, LEVEL)
        engine.start()
        for _ in range(400):
            engine.tick(0.005)
        engine.set_params({"turn": turn})
        for _ in range(400):                                    # ramped in, turn followed
            engine.tick(0.005)
        xs = []
        for _ in range(round(LEVEL.cycle_s / 0.005) + 1):
            q = dict(zip(ROBOT.joint_names, engine.tick(0.005), strict=True))
            leg = (0.0, *(q[f"r_{j}"] for j in ("hip_roll", "hip_pitch", "knee",
                                                 "ankle_pitch", "ankle_roll")))
            xs.append(leg_fk_full(ROBOT.geometry, "r", leg)[0][0])
        return max(xs) - min(xs)
    half_gap = ROBOT.geometry.hip_width / 2 + LEVEL.foot_spread
    assert right_travel(0.2) - right_travel(0.0) == pytest.approx(2 * 0.2 * half_gap, abs=1e-4)
