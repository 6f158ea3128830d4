"""`biped sim-gap` on a take recorded on the emulator, whose servos move by the servo model.

The oracle: the emulator integrates the servo law on plain floats in its own process on
the wall clock (sim/emulator/servo_dynamics.py); the sim replays the take's commands in
MuJoCo (sim/mujoco/pendulum.py: the law as an actuator, damping and frictionloss). When
the sim's robot file has the gains the driver wrote, the two agree to a small share of
the tracking error; with the P gain doubled or halved in the sim's robot file, the gap is
a large share of it.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from robot import cli
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot_file import load_robot
from robot.motion.takes import read_take
from sim.emulator.chain import Emulator

ROBOT = ROBOTS_DIR / "biped18-dynamixel.toml"
P_GAIN = 3000                     # the robot file's [bus.gains] position_p_gain
MIN_READS = 20


@pytest.fixture(scope="module")
def take(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A 3 s walk recorded on the emulated chain (servos moving by the model), at 100 Hz.
    On a loaded machine the loop's jam detection may stop a walk on the emulator early
    (exit 1; seen with the servos travelling at constant speed as well, at a load average
    of 15 on 2 cores): a take that stopped before 20 read-backs is recorded once more."""
    path = tmp_path_factory.mktemp("gap") / "walk.take.jsonl"
    for _ in range(2):
        with Emulator("dynamixel", load_robot(ROBOT), motion="model") as emu:
            code = cli.main(["walk", "--robot", str(ROBOT), "--bus", "dynamixel", "--port",
                             emu.port, "--seconds", "3", "--rate", "100", "--record",
                             str(path)])
        assert code in (0, 1)
        present = read_take(path).present
        if present is not None and np.isfinite(present).all(axis=1).sum() >= MIN_READS:
            break
    yield path


def gap(take: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> dict[str, float]:
    """Summed over the joints: RMS real-cmd, sim-cmd, real-sim [rad] (bench world)."""
    capsys.readouterr()
    assert cli.main(["sim-gap", str(take), "--world", "bench", "--json", *extra]) == 0
    rows = json.loads(capsys.readouterr().out)["joints"]
    return {k: sum(r[f"rms_{k}"] for r in rows) for k in ("real_cmd", "sim_cmd", "real_sim")}


def robot_with_p(tmp_path: Path, p_gain: int) -> Path:
    text = ROBOT.read_text()
    assert f"position_p_gain = {P_GAIN}" in text
    out = tmp_path / f"p{p_gain}.toml"
    out.write_text(text.replace(f"position_p_gain = {P_GAIN}", f"position_p_gain = {p_gain}"))
    return out


def test_the_take_stores_every_read_back(take: Path) -> None:
    taken = read_take(take)
    assert taken.present is not None
    ticks = np.flatnonzero(np.isfinite(taken.present).all(axis=1))
    assert len(ticks) >= MIN_READS
    assert int(np.median(np.diff(ticks))) == taken.header.read_every
    # read back: near the commands, not equal to them (the servos lag)
    diff = np.abs(taken.present[ticks] - taken.q[ticks])
    assert 0 < float(diff.max()) < 0.2


def test_same_model_small_gap(take: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Measured: real-sim 0.18 of real-cmd (2.2 of 12.2 deg summed RMS on a 4 s walk)."""
    g = gap(take, capsys)
    assert g["real_cmd"] > np.radians(3.0)          # the servos lagged visibly
    assert g["real_sim"] < 0.3 * g["real_cmd"], g


@pytest.mark.parametrize("p_gain", [2 * P_GAIN, P_GAIN // 2])
def test_other_gains_in_the_sim_show(take: Path, tmp_path: Path, p_gain: int,
                                     capsys: pytest.CaptureFixture[str]) -> None:
    """Measured: doubled P, real-sim 0.46 of real-cmd; halved, 0.70."""
    same = gap(take, capsys)
    other = gap(take, capsys, "--robot", str(robot_with_p(tmp_path, p_gain)))
    assert other["real_sim"] > 0.38 * other["real_cmd"], other
    assert other["real_sim"] > 1.5 * same["real_sim"]
    assert (other["sim_cmd"] < same["sim_cmd"]) == (p_gain > P_GAIN)   # stiffer: tracks better


def test_a_take_without_read_backs_is_one_line(tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "sim.take.jsonl"
    assert cli.main(["walk", "--robot", str(ROBOT), "--seconds", "0.5", "--record",
                     str(path)]) == 0
    lines = [json.loads(x) for x in path.read_text().splitlines()]
    stripped = [{k: v for k, v in x.items() if k != "present"} for x in lines]
    path.write_text("\n".join(json.dumps(x) for x in stripped) + "\n")
    capsys.readouterr()
    assert cli.main(["sim-gap", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert re.search(r"no read-back positions .*--record", err), err
