"""The bundled LX-16A biped (biped18-lx) walks 60 s in the MuJoCo sim at the rate its
LX wire carries (50 Hz for 18 servos: docs/hardware.md, "LX").

The acceptance criteria of the default robot (tests/test_walk_sim.py: 0.10 m/s, drift
<= 10 % of the distance, heading within 15 deg), the speed scaled by leg length: this
robot's thigh + shin is 0.16 m against the default's 0.22 m, so 0.07 m/s."""

from __future__ import annotations

import json

import pytest

from robot.cli import main
from robot.config.robot_file import load_robot


def test_the_lx16a_biped_walks_60s_at_the_lx_rate(capsys: pytest.CaptureFixture[str]) -> None:
    robot = load_robot("biped18-lx")
    assert (robot.bus.kind, robot.bus.model) == ("lx", "LX-16A")
    assert main(["walk", "--json", "--robot", "biped18-lx", "--seconds", "60",
                 "--rate", "50"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["fell"] is False and r["stop_reason"] == "completed"
    leg = robot.geometry.thigh + robot.geometry.shin
    assert r["speed_m_s"] >= 0.10 * leg / 0.22
    assert abs(r["lateral_drift_m"]) <= 0.10 * r["distance_m"]
    assert abs(r["heading_change_deg"]) <= 15.0
