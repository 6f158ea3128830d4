"""`biped robustness --push-map`: the bisection by hand, the options' refusals, and the
quick map end to end (two directions, two phases, real walks in worker processes), one of
its cells walked again by hand with `biped walk --push AT:JX,JY`."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

from robot.config.gait_file import load_gait
from robot.tuning.push_map import (
    QUICK_AT_S,
    QUICK_DIRECTIONS,
    QUICK_PHASES,
    QUICK_RESOLUTION_N_S,
    largest,
)


def test_the_bisection_finds_the_largest_survived_impulse_on_its_grid() -> None:
    """Survival up to 1.23 N*s: from [0, 1.0] it widens to 2.0, then halves to the
    largest multiple of 0.05 below 1.23, 1.20, never trying an impulse twice."""
    tried: list[float] = []

    def ok(j: float) -> bool:
        tried.append(j)
        return j <= 1.23
    assert largest(ok, 1.0, 0.05) == 1.2
    assert tried == [1.0, 2.0, 1.5, 1.25, 1.1, 1.2]
    assert len(set(tried)) == len(tried)
    assert largest(lambda j: j <= 0.31, 2.0, 0.05) == 0.3
    assert largest(lambda j: j <= 0.0, 2.0, 0.05) == 0.0
    assert largest(lambda j: True, 2.0, 0.05) == 10.0          # the --push range's end
    # The bracket's top rounds up to the grid: 0.93 -> 0.95.
    tried.clear()
    largest(ok, 0.93, 0.05)
    assert tried[0] == 0.95


def biped(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "robot.cli", *args], capture_output=True,
                          text=True, timeout=300, env={"MUJOCO_GL": "egl", "PATH": ""})


@pytest.mark.parametrize("args, needle", [
    (("--push-map", "--directions", "0,400"), "--directions"),
    (("--push-map", "--phases", "0.5,1.0"), "--phases"),
    (("--push-map", "--phases", "half"), "--phases"),
    (("--directions", "0,90"), "--push-map"),
])
def test_bad_map_options_are_one_line_and_exit_2(args: tuple[str, ...], needle: str) -> None:
    r = biped("robustness", *args)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], r.stderr
    assert r.stdout == ""


def test_the_quick_map_runs_and_any_cell_walks_again_by_hand() -> None:
    r = biped("robustness", "--push-map", "--quick", "--json", "--jobs", "2")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    cells = out["cells"]
    assert {(c["direction_deg"], c["phase"]) for c in cells} == {
        (d, p) for d in QUICK_DIRECTIONS for p in QUICK_PHASES}
    cycle = load_gait("walk").params.cycle_s
    for c in cells:
        assert c["balance"] is True
        assert c["at_s"] == pytest.approx(QUICK_AT_S + c["phase"] * cycle, abs=1e-3)
        lim = c["limit_n_s"]
        assert set(lim) == {"0", "1", "2"}
        assert 0.0 <= lim["0"] <= lim["1"] <= lim["2"]
        assert lim["1"] > 0.3            # a step can take some push at any moment
        # on the bisection's grid, and every impulse it walked is in its record
        assert c["survived_n_s"] / QUICK_RESOLUTION_N_S == pytest.approx(
            round(c["survived_n_s"] / QUICK_RESOLUTION_N_S), abs=1e-6)
        verdicts = {w["impulse_n_s"]: w["verdict"] for w in c["walks"]}
        assert all(verdicts[j] == "walks" for j in verdicts if j <= c["survived_n_s"])
        above = [j for j in verdicts if j > c["survived_n_s"]]
        assert above and all(verdicts[j] != "walks" for j in above)
    # The cell with the largest survived push, walked by hand: it walks on.
    best = max(cells, key=lambda c: c["survived_n_s"])
    a = math.radians(best["direction_deg"])
    j = best["survived_n_s"]
    push = f"{best['at_s']:.3f}:{j * math.cos(a):.6f},{j * math.sin(a):.6f}"
    w = biped("walk", "--seconds", f"{best['at_s'] + 2.0:.3f}", "--push", push,
              "--stop-on-fall", "--json")
    assert w.returncode == 0, w.stderr
    walk = json.loads(w.stdout)
    assert walk["fell"] is False
    assert walk["world"]["pushes_applied"][0]["state"]["feet"][0]["sole"]
