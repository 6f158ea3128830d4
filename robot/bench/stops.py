"""The stop study (`biped bench --only sim`, issue 32 item 5): a walk told to stop at 16
moments of its step, on every bundled robot and every 5-DoF variant (robot.bench
.variants), as `biped walk --seconds S --json` walks it (balance on where the robot has
an IMU): how far the robot turns from the stop request to the end of the run
(``stop_heading_change_deg`` of the walk summary: the ramp-out and the move to the rest
pose) and how long the balance held it braced after the stop (``stop_braced_s``). The
goal: within STOP_HEADING_DEG, never braced, on flat ground with no push.
"""

from __future__ import annotations

import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from robot.bench.variants import FIVE_DOF, write_five_dof
from robot.bus.factory import make_bus
from robot.config.bundled import ROBOTS_DIR, robot_names
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.run.run import execute
from robot.run.spec import RunOptions
from robot.run.walk import walk_imu, walk_spec, walk_summary

#: The walk stops this long [s of gait] plus a fraction of a cycle after it starts: well
#: after the rhythm is learned (the balance's stepping acts), as the suite's pushes.
STOP_AT_S = 8.0
STOP_PHASES = tuple(k / 16 for k in range(16))
QUICK_PHASES = (0.0, 0.5)
#: The stop's goal: heading within this [deg] from the stop request to the end.
STOP_HEADING_DEG = 2.0


def stop_walk(robot: str, phase: float, *, gait: str = "walk",
              changes: Mapping[str, float] | None = None) -> dict[str, Any]:
    """One walk of robot ``robot`` (name or path) stopped at STOP_AT_S + ``phase`` cycles
    (``changes``: gait parameters set on the preset): its stop's heading change [deg],
    braced time after the stop [s], fall."""
    r = load_robot(robot)
    params = load_gait(gait).for_robot(r)
    if changes:
        params = params.replace(changes, where="stop study")
    seconds = float(f"{STOP_AT_S + phase * params.cycle_s:.3f}")
    bus = make_bus("sim", robot=r, realtime=False, view=False)
    spec = walk_spec(r, params, bus, gait=gait, imu=walk_imu(r, bus),
                     options=RunOptions(seconds=seconds))
    s = walk_summary(spec, execute(spec), gait=gait)
    turn = s.get("stop_heading_change_deg")
    return {"phase": phase, "seconds": seconds, "fell": s["fell"],
            "stop_heading_deg": None if turn is None else round(float(turn), 2),
            "stop_braced_s": round(float(s["stop_braced_s"]), 3),
            "ok": (not s["fell"] and turn is not None and abs(turn) <= STOP_HEADING_DEG
                   and s["stop_braced_s"] == 0.0)}


def robots_and_variants(folder: Path) -> dict[str, str]:
    """Every bundled robot (its path) and the 5-DoF variants written to ``folder``."""
    out = {name: str(ROBOTS_DIR / f"{name}.toml") for name in robot_names()}
    out.update({f"{name} 5-DoF": str(write_five_dof(name, folder)) for name in FIVE_DOF})
    return out


def run_stops(*, quick: bool = False, phases: Sequence[float] | None = None
              ) -> dict[str, Any]:
    """The stop study: per robot, the worst stop and every stop; ``all_ok``."""
    phs = tuple(phases) if phases is not None else (QUICK_PHASES if quick else STOP_PHASES)
    out: dict[str, Any] = {"stop_at_s": STOP_AT_S, "goal_deg": STOP_HEADING_DEG}
    ok = True
    with tempfile.TemporaryDirectory() as folder:
        for name, path in robots_and_variants(Path(folder)).items():
            rows = [stop_walk(path, ph) for ph in phs]
            worst = max((abs(r["stop_heading_deg"]) for r in rows
                         if r["stop_heading_deg"] is not None), default=None)
            out[name] = {"worst_deg": worst, "ok": all(r["ok"] for r in rows),
                         "braced": sum(r["stop_braced_s"] > 0 for r in rows),
                         "stops": rows}
            ok = ok and out[name]["ok"]
    out["all_ok"] = ok
    return out
