"""`biped curves`: the CSV has t, every channel of equations.md in table order, then
q_<joint>; the channel columns are the printed formulas for the preset's parameters."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_gait import CHANNEL_NAMES, close, printed

from robot.cli import main
from robot.config.bundled import DEFAULT_ROBOT, ROBOTS_DIR, gait_names
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine


def read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array(rows[1:], dtype=float)


def expected_header(robot_path: Path) -> list[str]:
    return ["t", *CHANNEL_NAMES, *(f"q_{n}" for n in load_robot(robot_path).joint_names)]


@pytest.mark.parametrize("name", gait_names())
def test_curves_csv_is_the_printed_formulas(tmp_path: Path, name: str,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / f"{name}.csv"
    assert main(["curves", "--gait", name, "--seconds", "3", "--rate", "50",
                 "--out", str(out)]) == 0
    assert str(out) in capsys.readouterr().out
    header, data = read_csv(out)
    assert header == expected_header(DEFAULT_ROBOT)
    t = data[:, 0]
    assert np.array_equal(t, np.arange(151) / 50.0)
    params = load_gait(name).params
    want = printed(t, params.as_dict())
    for i, ch in enumerate(CHANNEL_NAMES, start=1):
        assert close(data[:, i], want[ch]), (name, ch)
    # The joint columns are the engine's joint angles, written at full precision.
    _, q = GaitEngine(load_robot(DEFAULT_ROBOT), params).curves(t)
    assert np.array_equal(data[:, 1 + len(CHANNEL_NAMES):], q.T)


def test_curves_console_script_with_the_feetech_robot(tmp_path: Path) -> None:
    robot = ROBOTS_DIR / "biped18-feetech.toml"
    out = tmp_path / "walk.csv"
    exe = Path(sys.executable).with_name("biped")
    proc = subprocess.run([str(exe), "curves", "--robot", str(robot), "--seconds", "1",
                           "--out", str(out)], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    header, data = read_csv(out)
    assert header == expected_header(robot)
    assert data.shape == (101, len(header))
    want = printed(data[:, 0], load_gait("walk").params.as_dict())
    assert all(close(data[:, 1 + i], want[ch]) for i, ch in enumerate(CHANNEL_NAMES))


def test_curves_unknown_preset_is_one_clear_line(tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["curves", "--gait", "sprint", "--out", str(tmp_path / "x.csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err
    assert err.startswith("biped curves: error:") and "'sprint'" in err
    assert ", ".join(gait_names()) in err
    assert not (tmp_path / "x.csv").exists()
