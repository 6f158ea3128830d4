"""A robot file's [balance] gains: validated like every field, and applied under the
gait preset's own values and --set (SPECS default < robot < preset < --set)."""

from __future__ import annotations

import argparse
import tomllib
from pathlib import Path

import pytest

from robot.commands.common import params_from
from robot.config.bundled import ROBOTS_DIR
from robot.config.gait_file import Gait, gait_to_toml, parse_gait
from robot.config.params import SPECS
from robot.config.robot_file import load_robot, parse_robot
from robot.errors import ConfigError

BASE = tomllib.loads((ROBOTS_DIR / "biped18-dynamixel.toml").read_text())


def robot_with(balance: dict[str, object]):  # type: ignore[no-untyped-def]
    return parse_robot({**BASE, "balance": balance}, source="r.toml")


def test_balance_gains_are_read_and_checked() -> None:
    assert robot_with({"bal_step_gain": 1.2}).balance == {"bal_step_gain": 1.2}
    assert load_robot("biped18-feetech").balance == {} or all(
        SPECS[k].group == "balance feedback" for k in load_robot("biped18-feetech").balance)
    with pytest.raises(ConfigError) as e:
        robot_with({"sway": 0.02})
    msg = str(e.value)
    assert msg.startswith("r.toml: balance.sway: not a balance gain") and "bal_step_gain" in msg
    with pytest.raises(ConfigError, match=r"r.toml: balance.bal_step_gain: bal_step_gain = 9 "
                                          r"is outside \[0, 3\]"):
        robot_with({"bal_step_gain": 9})
    with pytest.raises(ConfigError, match="unknown gait parameter 'bal_nope'"):
        robot_with({"bal_nope": 1.0})


def test_precedence_default_robot_preset_set(tmp_path: Path) -> None:
    robot = robot_with({"bal_step_gain": 1.2, "bal_hold_xi": 0.04})
    preset = tmp_path / "mine.toml"
    preset.write_text('name = "mine"\n[mapping]\nbal_hold_xi = 0.02\nsway = 0.02\n')
    args = argparse.Namespace(gait=str(preset), set=[])
    gait, p = params_from(args, robot)
    assert gait.given == {"bal_hold_xi", "sway"}
    assert p.bal_step_gain == 1.2          # from the robot (the preset does not name it)
    assert p.bal_hold_xi == 0.02           # the preset's own wins
    assert p.bal_brace_xi == SPECS["bal_brace_xi"].default
    args.set = ["bal_step_gain=0.5"]
    assert params_from(args, robot)[1].bal_step_gain == 0.5   # --set wins over all
    # A written preset names every parameter: the robot's gains no longer apply to it.
    full = parse_gait(tomllib.loads(gait_to_toml(Gait("full", p))), source="full.toml")
    assert full.for_robot(robot) == full.params
