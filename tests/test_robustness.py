"""`biped robustness`: the suite's conditions, and a --quick run end to end (real walks
in MuJoCo, in worker processes) that must survive what the balance loop is for."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from robot.config.gait_file import load_gait
from robot.config.params import SPECS
from robot.tuning.conditions import STAIRS_REACH_M, STAIRS_S, SWITCHES_S
from robot.tuning.robustness import (
    PUSH_AT_S,
    STRAIGHT_S,
    WALK_ON_SHARE,
    Condition,
    Outcome,
    conditions,
    judge,
    straightness,
    survival_table,
)

WALK = load_gait("walk").params


def test_every_parameter_condition_is_inside_its_documented_range() -> None:
    seen = set()
    for c in conditions(WALK):
        if c.group != "params +/-20 %":
            continue
        name, value = c.args[1].split("=")
        spec = SPECS[name]
        v = float(value)
        assert spec.lo <= v <= spec.hi, c.name
        assert v != getattr(WALK, name), c.name          # a real change
        seen.add(name)
    # stance 0.88 +20 % = 1.056 is outside [0.6, 0.99]: clipped, not dropped or invalid.
    assert "stance +20 % (range: 0.99)" in {c.name for c in conditions(WALK)}
    assert {"vM", "Slgt_R", "Fhgt_L", "sway", "stance"} <= seen


def test_the_full_suite_has_every_group_of_the_issue() -> None:
    groups = {c.group for c in conditions(WALK)}
    assert groups == {"flat", "slope", "cross slope", "bumps", "push forward",
                      "push backward", "push left", "push right", "push 1.5 N*s",
                      "params +/-20 %", "latency", "imu noise", "flat 60 s", "friction",
                      "mass", "stairs", "preset switches"}
    hard = [c for c in conditions(WALK) if c.group == "push 1.5 N*s"]
    pushes = [c for c in conditions(WALK) if c.group.startswith("push ")
              and c not in hard]
    assert len(pushes) == 16 and len(hard) == 16           # 4 directions x 4 phases each

    def push(c: Condition) -> tuple[float, float, float]:
        at, j = c.args[1].split(":")
        jx, jy = j.split(",")
        return float(at), float(jx), float(jy)
    assert sorted(push(c) for c in hard) == sorted((t, 1.5 * jx, 1.5 * jy)
                                                   for t, jx, jy in map(push, pushes))
    times = sorted({float(c.args[1].split(":")[0]) for c in pushes})
    assert times[0] == PUSH_AT_S
    assert times[-1] == pytest.approx(PUSH_AT_S + 0.75 * WALK.cycle_s, abs=1e-3)
    long = [c for c in conditions(WALK) if c.seconds is not None]
    assert [c.seconds for c in long] == [STRAIGHT_S, STAIRS_S, SWITCHES_S]
    stairs, switches = long[1:]
    assert stairs.args == ("--stairs", "0.015,3") and stairs.reach_m == STAIRS_REACH_M
    # Past the last riser down of the world it builds: the landing (0.30 m) after two
    # treads (0.25 m) up and two down, from the first riser at 0.30 m.
    assert 0.30 + 4 * 0.25 + 0.30 < STAIRS_REACH_M < 0.30 + 4 * 0.25 + 0.30 + 0.10
    assert switches.args == ("--switch", "4:jog", "--switch", "7:crouch",
                             "--switch", "10:walk")
    assert not {"stairs", "preset switches"} & {c.group for c in conditions(WALK, quick=True)}


def test_straightness_judges_heading_and_drift_against_the_goal() -> None:
    flat = Condition("flat 60 s", "flat 60 s", seconds=STRAIGHT_S)

    def run(heading: float, drift: float, *, balance: bool = True) -> Outcome:
        return Outcome(flat, balance, False, None, 6.0, heading,
                       summary={"lateral_drift_m": drift})
    assert straightness([run(4.9, 0.29)])[True]["ok"]
    assert not straightness([run(5.1, 0.0)])[True]["ok"]
    assert not straightness([run(0.0, -0.31)])[True]["ok"]      # 5.2 % of 6 m
    assert straightness([run(0.0, -0.31)])[True]["drift_ratio"] == pytest.approx(0.31 / 6)


def test_a_pushed_run_counts_only_if_it_walks_on() -> None:
    """By hand: the flat walk made 0.100 m/s with balance and 0.080 open loop; a pushed
    run survives at 0.090 (>= 0.85 x 0.100) and not at 0.080 nor standing still (0.005);
    open loop 0.070 >= 0.85 x 0.080 = 0.068 survives. A slope run is not a push: 0.02
    m/s survives. Every push group is judged; no other group is."""
    assert WALK_ON_SHARE == 0.85
    pushes = [c for c in conditions(WALK) if c.group.startswith("push")]
    assert len(pushes) == 32 and all(c.walk_on for c in pushes)
    assert not any(c.walk_on for c in conditions(WALK) if c not in pushes)
    flat, push, slope = Condition("flat", "flat"), pushes[0], Condition("slope", "slope")

    def run(c: Condition, speed: float, *, balance: bool = True, fell: bool = False
            ) -> Outcome:
        return Outcome(c, balance, fell, summary={"speed_m_s": speed})
    runs = judge([run(flat, 0.100), run(flat, 0.080, balance=False), run(push, 0.090),
                  run(push, 0.080), run(push, 0.005), run(push, 0.070, balance=False),
                  run(slope, 0.02), run(push, 0.2, fell=True)])
    assert [o.survived for o in runs] == [True, True, True, False, False, True, True, False]
    assert [o.stood for o in runs] == [False, False, False, True, True, False, False, False]
    table = dict(survival_table(runs))
    assert table[push.group] == {True: (1, 4), False: (1, 1)}
    # No flat walk that stayed up to compare with: no pushed run walks on.
    alone = judge([run(flat, 0.1, fell=True), run(push, 0.09)])
    assert not alone[1].survived and alone[1].stood


@pytest.fixture(scope="module")
def quick(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    png = tmp_path_factory.mktemp("robustness") / "suite.png"
    proc = subprocess.run([sys.executable, "-m", "robot.cli", "robustness", "--quick",
                           "--json", "--out", str(png)], capture_output=True, text=True,
                          timeout=900, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout), png


def test_quick_suite_runs_with_and_without_balance(quick: tuple[dict, Path]) -> None:
    result, png = quick
    runs = result["runs"]
    assert all(r["error"] == "" for r in runs)
    assert {r["balance"] for r in runs} == {True, False}
    assert len(runs) == 2 * len(conditions(WALK, quick=True))
    assert png.stat().st_size > 10_000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("name", ["flat", "slope +5 deg", "slope -5 deg",
                                  "cross slope +4 deg", "latency 20 ms", "imu noise x3"])
def test_with_balance_the_quick_cases_survive(quick: tuple[dict, Path], name: str) -> None:
    run = next(r for r in quick[0]["runs"] if r["condition"] == name and r["balance"])
    assert run["fell"] is False, run


def test_the_quick_suite_counts_a_push_only_if_it_walks_on(quick: tuple[dict, Path]) -> None:
    """Recomputed from the runs' own speeds: a push run survived iff it stayed up at
    WALK_ON_SHARE of its mode's flat walk; the groups count survivors by that."""
    result = quick[0]
    runs = result["runs"]
    flat = {r["balance"]: r["speed_m_s"] for r in runs if r["condition"] == "flat"}
    pushes = [r for r in runs if r["group"].startswith("push")]
    assert len(pushes) == 8 and all(r["walk_on"] for r in pushes)
    for r in pushes:
        walks = r["fell"] is False and r["speed_m_s"] >= WALK_ON_SHARE * flat[r["balance"]]
        assert r["survived"] is walks and r["stood"] is (r["fell"] is False and not walks), r
    for g, modes in result["groups"].items():
        for mode, cell in modes.items():
            mine = [r for r in runs if r["group"] == g and r["balance"] is (mode == "balance")]
            assert cell == {"survived": sum(r["survived"] for r in mine), "runs": len(mine)}


def test_the_quick_suite_gives_each_push_as_a_share_of_its_capture_limit(
        quick: tuple[dict, Path]) -> None:
    """Every pushed run (1 N*s) has the 0-, 1-, 2-step limits of its moment, in order, and
    its share of the 1-step one is 1 N*s over it; no other run has them."""
    for r in quick[0]["runs"]:
        if not r["group"].startswith("push"):
            assert "limit_n_s" not in r
            continue
        lim = r["limit_n_s"]
        assert 0.0 <= lim["0"] <= lim["1"] <= lim["2"] and lim["1"] > 0.3, r
        assert r["push_n_s"] == pytest.approx(1.0)
        assert r["share_of_1_step"] == pytest.approx(1.0 / lim["1"])


def test_the_5_deg_uphill_needs_the_balance_loop(quick: tuple[dict, Path]) -> None:
    """Open loop the walk falls on a 5 deg uphill (the issue's measurement); with the
    learned lean it walks on."""
    runs = {r["balance"]: r for r in quick[0]["runs"] if r["condition"] == "slope +5 deg"}
    assert runs[False]["fell"] is True and runs[True]["fell"] is False
