"""sim.mujoco.effort: energy and knee load from actuator forces and joint rates, checked against
hand-computed sums on set values, and on the real walk's summary."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from robot import cli
from robot.config.robot_file import load_robot
from sim.mujoco.effort import EffortMonitor
from sim.mujoco.mjcf import build_mjcf


def test_energy_and_knee_load_are_the_hand_sums() -> None:
    robot = load_robot("biped18-dynamixel")
    model = build_mjcf(robot).model()
    data = SimpleNamespace(actuator_force=np.zeros(model.nu), qvel=np.zeros(model.nv))
    mon = EffortMonitor(model, data, robot)   # type: ignore[arg-type]
    knee_r, knee_l = model.actuator("r_knee").id, model.actuator("l_knee").id
    hip = model.actuator("r_hip_pitch").id
    dof = {n: model.jnt_dofadr[model.joint(n).id] for n in ("r_knee", "l_knee", "r_hip_pitch")}
    # the servo model's stall torque at the robot's supply: kt V max_duty / R
    knee = robot.joint("r_knee")
    stall = robot.servo_physics(knee).stall_torque(robot.voltage(knee))
    mon.update(0.0)                                   # start: no span yet
    data.actuator_force[[knee_r, knee_l, hip]] = (0.7, -0.35, 0.2)
    data.qvel[[dof["r_knee"], dof["l_knee"], dof["r_hip_pitch"]]] = (2.0, 1.0, -3.0)
    mon.update(0.005)
    mon.update(0.010)
    # |0.7 * 2| + |-0.35 * 1| + |0.2 * -3| = 2.35 W over 2 ticks of 5 ms
    assert mon.energy_j == pytest.approx(2.35 * 0.010)
    # knees: tick 1 zero; ticks 2, 3: (0.7 + 0.35) / 2 / stall
    want = 100.0 * (0.0 + 2 * (0.7 + 0.35) / 2 / stall) / 3
    s = mon.summary(distance_m=0.5)
    assert s["knee_load_pct"] == pytest.approx(want)
    assert s["energy_per_m"] == pytest.approx(2.35 * 0.010 / 0.5)
    assert mon.summary(distance_m=0.0)["energy_per_m"] is None


def test_the_walk_summary_reports_effort(capsys: pytest.CaptureFixture[str],
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cli, "COMMANDS", ("walk",))
    assert cli.main(["walk", "--json", "--seconds", "2", "--no-balance"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["energy_j"] > 0.0 and 0.0 < r["knee_load_pct"] < 100.0
    assert r["energy_per_m"] == pytest.approx(r["energy_j"] / r["distance_m"])
