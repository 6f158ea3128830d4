"""An imported show on a servo bus (the pty emulator, the real vendor SDK): a kick past the
knee's limit, clamped by the import, plays through the same loop as a walk and ends safe,
judged from the servos' registers: torque off, every last goal inside the joint limits."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from test_import import _knee_bvh

import robot.cli as cli
from robot.config.robot_file import load_robot
from robot.servo.models import MODELS
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)


def test_an_imported_show_on_the_bus_ends_safe(emu: Emulator, robot_toml: Path,
                                               tmp_path: Path) -> None:
    robot = load_robot(robot_toml)
    hi = np.degrees(robot.joint("r_knee").max_rad)
    degs = [30.0] * 12 + [hi + 15.0] * 6 + [30.0] * 12
    src, take = tmp_path / "kick.bvh", tmp_path / "kick.take.jsonl"
    _knee_bvh(src, degs)
    assert cli.main(["import", str(src), "--robot", str(robot_toml), "--out", str(take)]) == 0
    assert cli.main(["play", str(take), "--bus", emu.protocol, "--port", emu.port]) == 0
    per_rad = MODELS[robot.bus.model].ticks_per_rad
    for j in robot.joints:
        regs = emu.registers(j.servo_id)
        assert regs["torque_enable"] == 0, j.name
        lo, hi_t = sorted(j.zero_ticks + j.sign * q * per_rad for q in (j.min_rad, j.max_rad))
        assert lo - 1 <= regs["goal_position"] <= hi_t + 1, (j.name, regs["goal_position"])
