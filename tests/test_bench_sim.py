"""`biped bench --only sim`: a smoke run reports a realtime factor and the physics share
for both robots, open loop and with balance (values are measured, never asserted), and
walks every bundled preset on every bundled robot (5 s here; 60 s in the full bench)."""

from __future__ import annotations

from robot.bench.sim import run_sim_bench
from robot.config.bundled import gait_names, robot_names


def test_the_sim_bench_reports_every_configuration() -> None:
    out = run_sim_bench(quick=True)
    keys = {k for k in out if k.startswith("biped18")}
    assert keys == {f"biped18-{r} {m}" for r in ("dynamixel", "feetech")
                    for m in ("open loop", "balance")}
    for k in keys:
        row = out[k]
        assert row["realtime_factor_median"] > 0.0
        assert 0.0 < row["mj_step_share_of_loop"] < 1.0
    presets = out["presets"]
    assert presets["seconds"] == 5.0
    assert {k for k in presets if " " in k} == {f"{r} {g}" for r in robot_names()
                                                for g in gait_names()}
    # a 5 s smoke walk of a bundled preset does not fall (the 60 s figures: docs/servos.md)
    assert presets["all_walked"] is True, presets
