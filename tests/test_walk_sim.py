"""`biped walk` on the MuJoCo bus: the acceptance criteria of the default robot and presets.

Each run is a real physics simulation of the full pipeline (gait → IK → ticks → sim bus →
streamer); 60 simulated seconds take a few wall seconds.
"""

from __future__ import annotations

import json
import math

import pytest

from robot.cli import main
from robot.config.bundled import ROBOTS_DIR

REQUIRED = ("distance_m", "speed_m_s", "fell", "heading_change_deg", "lateral_drift_m",
            "ticks", "rate_hz", "period_error_p50_ms", "period_error_p99_ms", "overruns",
            "realtime_factor")


def walk(capsys: pytest.CaptureFixture[str], *args: str) -> dict:
    assert main(["walk", "--json", *args]) == 0
    out = capsys.readouterr().out
    return json.loads(out)  # one JSON object and nothing else on stdout


def test_json_has_every_field(capsys: pytest.CaptureFixture[str]) -> None:
    r = walk(capsys, "--seconds", "2")
    assert set(REQUIRED) <= set(r)
    assert r["rate_hz"] == 200.0 and r["ticks"] > 400
    assert r["realtime_factor"] > 0


@pytest.mark.parametrize("robot", ["biped18-dynamixel.toml", "biped18-feetech.toml"])
def test_default_walk_walks_60s(capsys: pytest.CaptureFixture[str], robot: str) -> None:
    r = walk(capsys, "--seconds", "60", "--robot", str(ROBOTS_DIR / robot))
    assert r["fell"] is False
    assert r["speed_m_s"] >= 0.10
    assert abs(r["lateral_drift_m"]) <= 0.10 * r["distance_m"]
    assert abs(r["heading_change_deg"]) <= 15.0


@pytest.mark.parametrize("gait", ["crouch", "high_step", "march"])
def test_presets_stay_up_60s(capsys: pytest.CaptureFixture[str], gait: str) -> None:
    r = walk(capsys, "--seconds", "60", "--gait", gait)
    assert r["fell"] is False
    if gait == "march":
        assert r["displacement_m"] <= 0.10


@pytest.mark.parametrize("turn", [0.1, -0.1])
def test_turn_parameter_turns_the_commanded_way(capsys: pytest.CaptureFixture[str],
                                               turn: float) -> None:
    r = walk(capsys, "--seconds", "10", "--set", f"turn={turn}")
    assert r["fell"] is False
    # 0.1 rad per step, two steps per ~0.87 s cycle: ~2 rad in 10 s if no foot slipped;
    # ask for at least a third of it, in the commanded direction (+ = left).
    assert math.copysign(1.0, turn) * math.radians(r["heading_change_deg"]) > 0.7


def test_bad_set_is_refused_before_anything_moves(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["walk", "--json", "--set", "Slgt_R=99"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "Slgt_R" in captured.err and "outside" in captured.err


def test_side_step_and_backward_steer_the_commanded_way(capsys: pytest.CaptureFixture[str]) -> None:
    side = walk(capsys, "--seconds", "10", "--set", "side_step=0.02", "--set", "speed=0")
    assert side["fell"] is False
    assert side["lateral_drift_m"] > 0.1            # + = left
    assert abs(side["distance_m"]) < 0.5 * side["lateral_drift_m"]
    back = walk(capsys, "--seconds", "10", "--set", "speed=-1")
    assert back["fell"] is False
    assert back["distance_m"] < -0.5
