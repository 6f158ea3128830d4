"""The acceptance walk of a bundled robot: 60 s on the flat in the MuJoCo sim.

The default robot's criteria (tests/test_walk_sim.py: 0.10 m/s, drift <= 10 % of the
distance, heading within 15 deg), the speed scaled by leg length (thigh + shin against the
default's 0.22 m)."""

from __future__ import annotations

import json

import pytest

from robot.cli import main
from robot.config.robot_file import load_robot


def assert_walks_60s(name: str, capsys: pytest.CaptureFixture[str], *extra: str) -> None:
    robot = load_robot(name)
    assert main(["walk", "--json", "--robot", name, "--seconds", "60", *extra]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["fell"] is False and r["stop_reason"] == "completed"
    leg = robot.geometry.thigh + robot.geometry.shin
    assert r["speed_m_s"] >= 0.10 * leg / 0.22
    assert abs(r["lateral_drift_m"]) <= 0.10 * r["distance_m"]
    assert abs(r["heading_change_deg"]) <= 15.0
