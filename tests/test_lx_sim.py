"""The bundled LX-16A biped (biped18-lx) walks 60 s in the MuJoCo sim at the rate its
LX wire carries (50 Hz for 18 servos: docs/hardware.md, "LX").

The acceptance criteria of the default robot (tests/test_walk_sim.py: 0.10 m/s, drift
<= 10 % of the distance, heading within 15 deg), the speed scaled by leg length: this
robot's thigh + shin is 0.16 m against the default's 0.22 m, so 0.07 m/s."""

from __future__ import annotations

import pytest
from walk_criteria import assert_walks_60s

from robot.config.robot_file import load_robot


def test_the_lx16a_biped_walks_60s_at_the_lx_rate(capsys: pytest.CaptureFixture[str]) -> None:
    robot = load_robot("biped18-lx")
    assert (robot.bus.kind, robot.bus.model) == ("lx", "LX-16A")
    assert_walks_60s("biped18-lx", capsys, "--rate", "50")
