"""A 5-DoF robot for tests (docs/robots.md's worked example): the bundled legs-only robot
without hip yaw, with stronger XM430-W350 knees (mixed servo models) and a head pan servo
(id 20) held at ``HEAD_RAD``."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from robot.config.bundled import ROBOTS_DIR
from robot.config.robot import RobotConfig
from robot.config.robot_file import parse_robot

LEGS = ROBOTS_DIR / "biped12-legs.toml"
HEAD_RAD = 0.3


def five_dof_text() -> str:
    """The robot file's text."""
    s = LEGS.read_text()
    s = re.sub(r"(?ms)^\[joints\.[rl]_hip_yaw\].*?(?=^\[)", "", s)
    s = re.sub(r"(?m)^hip_yaw_link = .*\n", "", s)       # no hip yaw servo, no such link
    for side in "rl":
        s = s.replace(f"[joints.{side}_knee]\n", f'[joints.{side}_knee]\nmodel = "XM430-W350"\n')
    return s.replace("[rest]", f"""[joints.head_pan]
servo_id = 20
sign = 1
zero_ticks = 2048
min_rad = -1.0
max_rad = 1.0
max_speed_rad_s = 3.0
fixed_rad = {HEAD_RAD}

[rest]""")


def five_dof_with_head(tmp_path: Path) -> Path:
    """The robot file written to ``tmp_path``/five.toml."""
    path = tmp_path / "five.toml"
    path.write_text(five_dof_text())
    return path


def five_dof_robot() -> RobotConfig:
    """The robot, parsed from memory."""
    return parse_robot(tomllib.loads(five_dof_text()), source="five.toml")


def no_ankle_roll_text() -> str:
    """The bundled legs-only robot without ankle roll (hip yaw kept): the 5-DoF legs of
    the Open Duck Mini, on the box model."""
    return re.sub(r"(?ms)^\[joints\.[rl]_ankle_roll\].*?(?=^\[)", "", LEGS.read_text())


def no_ankle_roll_robot() -> RobotConfig:
    """That robot, parsed from memory."""
    return parse_robot(tomllib.loads(no_ankle_roll_text()), source="no-ankle-roll.toml")
