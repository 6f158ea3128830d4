"""`biped bench --only sim`: a smoke run reports a realtime factor and the physics share
for both robots, open loop and with balance (values are measured, never asserted), and
walks every bundled preset on every bundled robot (5 s here; 60 s in the full bench).

This file runs the whole bench with its presets walked on the last third of the robots
(``robot_names()[2::3]``); the other thirds are tests/test_bench_sim_presets_{0,1}.py
(tests/bench_presets.py), so that three workers walk them side by side."""

from __future__ import annotations

import pytest
from bench_presets import PARTS, assert_presets_walked, only_robots, part

from robot.bench.sim import run_sim_bench
from robot.config.bundled import robot_names


def test_the_three_parts_hold_every_bundled_robot_once() -> None:
    parts = [part(i) for i in range(PARTS)]
    assert sorted(r for p in parts for r in p) == robot_names() and all(parts)


def test_the_sim_bench_reports_every_configuration(monkeypatch: pytest.MonkeyPatch) -> None:
    robots = part(PARTS - 1)
    only_robots(monkeypatch, robots)
    out = run_sim_bench(quick=True)
    keys = {k for k in out if k.startswith("biped18")}
    assert keys == {f"biped18-{r} {m}" for r in ("dynamixel", "feetech")
                    for m in ("open loop", "balance")}
    for k in keys:
        row = out[k]
        assert row["realtime_factor_median"] > 0.0
        assert 0.0 < row["mj_step_share_of_loop"] < 1.0
    # a 5 s smoke walk of a bundled preset does not fall (the 60 s figures: docs/servos.md)
    assert_presets_walked(out["presets"], robots)
