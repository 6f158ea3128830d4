"""docs/push_grid.py --leg-gain: the robot file is walked with other gain registers on the
leg servos only (docs/robustness.md, issue 22, fourth pass). No sim: the copy is loaded
and each joint's gains read as the driver would write them (RobotConfig.gains)."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import pytest

from robot.config.robot_file import load_robot
from robot.errors import ConfigError

SCRIPT = Path(__file__).resolve().parents[1] / "docs" / "push_grid.py"


def push_grid_script() -> ModuleType:
    spec = importlib.util.spec_from_file_location("push_grid_script", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_leg_gains_go_to_the_twelve_leg_servos_and_nothing_else(tmp_path: Path) -> None:
    grid = push_grid_script()
    path = grid.with_leg_gains("biped18-dynamixel",
                               {"position_p_gain": 6000, "position_d_gain": 8000}, tmp_path)
    robot = load_robot(path)
    gains = {j.name: robot.gains(j) for j in robot.joints}
    legs = [n for n in gains if n.split("_", 1)[1] in
            ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")]
    assert len(legs) == 12
    for name in legs:
        assert (gains[name]["position_p_gain"], gains[name]["position_d_gain"]) == (6000, 8000)
    # The arms keep the robot file's [bus.gains] P 3000 and the XL430's factory D 4000.
    for name in set(gains) - set(legs):
        assert (gains[name]["position_p_gain"], gains[name]["position_d_gain"]) == (3000, 4000)


def test_a_register_the_servo_lacks_is_one_line_naming_the_option(tmp_path: Path) -> None:
    grid = push_grid_script()
    with pytest.raises(ConfigError, match=r"^--leg-gain on biped18-feetech: .*position_p_gain"
                                          r".*valid: p_coefficient"):
        grid.with_leg_gains("biped18-feetech", {"position_p_gain": 6000}, tmp_path)
    with pytest.raises(ConfigError, match="--leg-gain p=6.5: give NAME=VALUE"):
        grid.parse_pairs("--leg-gain", ["p=6.5"], int)
