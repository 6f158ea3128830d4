"""A robot file's [gait]: the gait parameters its body needs, validated like every field
and applied over whatever preset is walked, under --set (preset < [gait] < --set); the
tuner leaves them alone (a tuned preset could not change them)."""

from __future__ import annotations

import argparse
import tomllib
from pathlib import Path

import pytest

from robot.commands.common import params_from
from robot.config.bundled import ROBOTS_DIR
from robot.config.gait_file import load_gait
from robot.config.params import SPECS
from robot.config.robot_file import parse_robot
from robot.errors import ConfigError
from robot.tuning.space import search_space

BASE = tomllib.loads((ROBOTS_DIR / "biped18-dynamixel.toml").read_text())


def robot_with(gait: dict[str, object], balance: dict[str, object] | None = None):  # type: ignore[no-untyped-def]
    return parse_robot({**BASE, "gait": gait, "balance": balance or {}}, source="r.toml")


def test_gait_parameters_are_read_and_checked() -> None:
    assert robot_with({"vM": 0.5, "sway": 0.01, "Wpos_R": 0.1}).gait == {
        "vM": 0.5, "sway": 0.01, "Apos_R": 0.1}            # aliases become canonical names
    assert parse_robot(BASE, source="r.toml").gait == {}
    with pytest.raises(ConfigError) as e:
        robot_with({"bal_step_gain": 0.5})
    msg = str(e.value)
    assert msg.startswith("r.toml: gait.bal_step_gain: not a gait parameter of the robot "
                          "(a balance gain belongs in [balance]); valid: ") and "sway" in msg
    assert "bal_step_gain" not in msg.split("valid: ")[1] and "turn" not in msg.split("valid: ")[1]
    with pytest.raises(ConfigError, match=r"r.toml: gait.turn: not a gait parameter of the "
                                          r"robot \(a steering command"):
        robot_with({"turn": 0.1})
    with pytest.raises(ConfigError, match=r"r.toml: gait.sway: sway = 0.5 is outside"):
        robot_with({"sway": 0.5})
    with pytest.raises(ConfigError, match="unknown gait parameter 'nope'"):
        robot_with({"nope": 1.0})
    with pytest.raises(ConfigError, match="given twice"):
        robot_with({"Apos_R": 0.1, "Wpos_R": 0.2})


def test_precedence_preset_robot_gait_set(tmp_path: Path) -> None:
    robot = robot_with({"vM": 0.5, "foot_spread": -0.01}, {"bal_hold_xi": 0.04})
    preset = tmp_path / "mine.toml"
    preset.write_text('name = "mine"\n[params]\nvM = 0.2\n[mapping]\nsway = 0.02\n'
                      'bal_hold_xi = 0.02\n')
    args = argparse.Namespace(gait=str(preset), set=[])
    _, p = params_from(args, robot)
    assert p.vM == 0.5                   # the robot's [gait] over the preset's own value
    assert p.foot_spread == -0.01        # ... and over the default the preset leaves
    assert p.sway == 0.02                # what [gait] does not name: the preset's
    assert p.bal_hold_xi == 0.02         # [balance] stays under the preset
    assert p.Slgt_R == SPECS["Slgt_R"].default
    args.set = ["vM=0.4"]
    assert params_from(args, robot)[1].vM == 0.4          # --set wins over all
    # Every bundled preset walks with the robot's values.
    for name in ("walk", "jog"):
        assert load_gait(name).for_robot(robot).vM == 0.5


def test_the_tuner_leaves_the_robots_gait_alone() -> None:
    p = load_gait("walk").params
    names = {k.name for k in search_space([], p, robot_gait={"vM", "Slgt_R", "Slgt_L"})}
    assert "vM" not in names and "Slgt" not in names and "sway" in names
    with pytest.raises(ConfigError, match=r"--param vM: vM is set by the robot file's \[gait\]"):
        search_space(["vM"], p, robot_gait={"vM"})
