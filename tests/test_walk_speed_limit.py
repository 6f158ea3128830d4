"""A walk says which joints its gait asked faster than their servos turn.

The loop holds every goal to the servo's speed (robot.loop.streamer: the slew limit,
``max_speed_rad_s`` per joint); `biped walk` reports, per joint, the time it did so
(``speed_limited_joints_s``, and a line of the summary). Two oracles, neither the loop's
own count: the gait's curves at the loop's rate (GaitEngine.curves, the joints whose step
exceeds the servo's speed: the Open Duck's knees under its own [gait], none on
biped18-dynamixel), and the record of what went to the wire (a held tick moves its joint
by exactly one slew step, and no tick moves it by more).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import robot.cli as cli
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine

RATE_HZ = 200.0


def too_fast(name: str) -> set[str]:
    """The joints whose gait curve (two steady cycles at the loop's rate) steps faster than
    the servo turns."""
    robot = load_robot(name)
    engine = GaitEngine(robot, load_gait("walk").for_robot(robot))
    t = np.arange(int(2 * engine.params.cycle_s * RATE_HZ) + 2) / RATE_HZ
    _, q = engine.curves(t, with_channels=False)
    speed = np.abs(np.diff(q, axis=1)).max(axis=1) * RATE_HZ
    return {j.name for j, v in zip(robot.joints, speed, strict=True) if v > j.max_speed_rad_s}


def walk(name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[dict, Path]:
    rec = tmp_path / "run.csv"
    assert cli.main(["walk", "--robot", name, "--seconds", "4", "--no-balance", "--json",
                     "--record", str(rec)]) == 0
    return json.loads(capsys.readouterr().out), rec


@pytest.mark.parametrize("name", ["open-duck-mini-v2", "biped18-dynamixel"])
def test_the_joints_asked_faster_than_their_servos_are_named(
        name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    want = too_fast(name)
    assert (name == "open-duck-mini-v2") == bool(want), want   # the Duck's knees; none else
    got, rec = walk(name, tmp_path, capsys)
    assert set(got["speed_limited_joints_s"]) == want, got["speed_limited_joints_s"]

    robot = load_robot(name)
    with rec.open() as f:
        rows = list(csv.DictReader(f))
    for j in robot.joints:
        cmd = np.array([float(r[f"cmd_{j.name}"]) for r in rows])
        moved = np.abs(np.diff(cmd))
        step = j.max_speed_rad_s / RATE_HZ
        assert moved.max() <= step * (1 + 1e-9), (j.name, moved.max(), step)   # at the wire
        held = int(np.count_nonzero(moved >= step * (1 - 1e-9)))
        said = got["speed_limited_joints_s"].get(j.name, 0.0) * RATE_HZ
        assert held == pytest.approx(said, abs=1), (j.name, held, said)


def test_the_summary_says_it(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["walk", "--robot", "open-duck-mini-v2", "--seconds", "3",
                     "--no-balance"]) == 0
    line = next(s for s in capsys.readouterr().out.splitlines() if "joint limits" in s)
    assert "asked faster than the servo turns" in line and "r_knee" in line and "l_knee" in line
