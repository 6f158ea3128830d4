"""`--model-names` (biped walk, biped play): an imported robot's record carries its joints
in its model's own terms too (robot/config/model_angles.py; robot/loop/recorder.py's
``model_cmd_<model joint>`` and ``model_present_<model joint>`` columns). Checked before
anything moves: one line, exit 2, for a box robot (it has no model) or a record that is
not a .csv or .jsonl."""

from __future__ import annotations

import argparse

from robot.config.model_angles import ModelAngles
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.loop.mcap_recorder import is_mcap
from robot.motion.takes import is_take


def add_model_names_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument("--model-names", action="store_true",
                   help="an imported robot: a .csv or .jsonl --record adds each joint under "
                        "its model's name, in the model's convention (model_cmd_<joint>, "
                        "model_present_<joint>) [rad]")


def model_for(args: argparse.Namespace, robot: RobotConfig) -> ModelAngles | None:
    """The model angles a --model-names record writes (None: not asked for)."""
    if not getattr(args, "model_names", False):
        return None
    record = getattr(args, "record", None)
    if not record or is_take(record) or is_mcap(record):
        raise ConfigError("--model-names: adds columns to a .csv or .jsonl record; give "
                          "--record FILE.csv or --record FILE.jsonl"
                          + (f" (not {record})" if record else ""))
    return ModelAngles.of(robot, what="--model-names")
