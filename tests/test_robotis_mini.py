"""The bundled ROBOTIS MINI (robotis-mini): 16 XL-320s on Dynamixel Protocol 2.0 with the
XL-320's table, 5-DoF legs, 3-DoF arms; it walks 60 s in the MuJoCo sim with the
identified XL-320.

The acceptance walk (tests/walk_criteria.py), the speed scaled by leg length: thigh + shin
0.117 m against the default's 0.22 m, 0.053 m/s."""

from __future__ import annotations

import pytest
from walk_criteria import assert_walks_60s

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
    assert_walks_60s("robotis-mini", capsys)
