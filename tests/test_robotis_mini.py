"""The bundled ROBOTIS MINI (robotis-mini): 16 XL-320s on Dynamixel Protocol 2.0 with the
XL-320's table, 5-DoF legs, 3-DoF arms; it walks 60 s in the MuJoCo sim with the
identified XL-320.

The acceptance criteria of the default robot (tests/test_walk_sim.py: 0.10 m/s, drift
<= 10 % of the distance, heading within 15 deg), the speed scaled by leg length as for
the LX biped (tests/test_lx_sim.py): thigh + shin 0.117 m against 0.22 m, 0.053 m/s."""

from __future__ import annotations

import json

import pytest

from robot.cli import main
from robot.config.robot_file import load_robot


def test_the_robotis_mini_is_16_xl320s() -> None:
    robot = load_robot("robotis-mini")
    assert (robot.bus.kind, robot.bus.model, robot.bus.baud) == ("dynamixel", "XL-320",
                                                                  1_000_000)
    assert len(robot.joints) == 16 and sorted(robot.ids) == list(range(1, 17))
    assert not any(j.name.endswith("hip_yaw") for j in robot.joints)
    assert {robot.servo(j).name for j in robot.joints} == {"XL-320"}
    assert {j.zero_ticks for j in robot.joints} == {512}     # the middle of 0..1023
    assert robot.mass.total == pytest.approx(0.644)


def test_the_robotis_mini_walks_60s(capsys: pytest.CaptureFixture[str]) -> None:
    robot = load_robot("robotis-mini")
    assert main(["walk", "--json", "--robot", "robotis-mini", "--seconds", "60"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["fell"] is False and r["stop_reason"] == "completed"
    leg = robot.geometry.thigh + robot.geometry.shin
    assert r["speed_m_s"] >= 0.10 * leg / 0.22
    assert abs(r["lateral_drift_m"]) <= 0.10 * r["distance_m"]
    assert abs(r["heading_change_deg"]) <= 15.0
