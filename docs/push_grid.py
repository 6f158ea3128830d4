"""The push grid of issue 22: 4 directions x 4 phases at one impulse, walked as the
robustness suite walks them (robot.tuning.conditions.push_grid, robot.tuning.robustness.
run_condition: `biped walk --json --stop-on-fall`, 8 s + the phase + 2 s after the push,
the preset's own gains). Prints each case (survived, fall time, speed over the run) and
the total under the walking rule: a run counts only if it did not fall and its speed over
the run is at least the robot's line (0.082 m/s Dynamixel, 0.075 m/s Feetech: about 85 %
of its unpushed walk; docs/robustness.md, "Second pass").

Run: ``MUJOCO_GL=egl nice -n 5 .venv/bin/python docs/push_grid.py --robot
biped18-dynamixel --impulse 1.0 --gait walk --jobs 1 [--set bal_step_gain=0.5 ...]
[--open-loop]``
"""

from __future__ import annotations

import argparse
import sys
from concurrent.futures import ProcessPoolExecutor

from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.tuning.conditions import AFTER_PUSH_S, push_grid
from robot.tuning.robustness import Outcome, WalkJob, run_condition, worker_init

#: The walking line per robot [m/s]: a pushed run slower than this over the whole run
#: stood after the push (docs/robustness.md, issue 22, second pass).
WALK_LINE = {"biped18-dynamixel": 0.082, "biped18-feetech": 0.075}


def parse_set(items: list[str]) -> dict[str, float]:
    out = {}
    for item in items:
        name, _, value = item.partition("=")
        try:
            out[name] = float(value)
        except ValueError:
            raise SystemExit(f"--set {item}: give NAME=NUMBER") from None
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--robot", default="biped18-dynamixel")
    ap.add_argument("--impulse", type=float, default=1.0, help="[N*s]")
    ap.add_argument("--gait", default="walk")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="a gait parameter on top of the preset (repeatable)")
    ap.add_argument("--open-loop", action="store_true", help="balance off")
    ap.add_argument("--only", default="", help="run only cases whose name contains this")
    a = ap.parse_args()
    worker_init()
    robot = load_robot(a.robot)
    params = load_gait(a.gait).for_robot(robot)
    if a.set:
        params = params.replace(parse_set(a.set), where="--set")
    line = WALK_LINE.get(a.robot, 0.0)
    conds = [c for c in push_grid(params.cycle_s, a.impulse) if a.only in c.name]
    jobs = []
    for c in conds:
        assert c.world is not None
        jobs.append(WalkJob(a.robot, a.gait, params, c.world.pushes[0].at_s + AFTER_PUSH_S,
                            c, balance=not a.open_loop))
    if a.jobs > 1:
        with ProcessPoolExecutor(a.jobs, initializer=worker_init) as pool:
            outs: list[Outcome] = list(pool.map(run_condition, jobs))
    else:
        outs = [run_condition(j) for j in jobs]
    ok = 0
    for o in outs:
        speed = float(o.summary.get("speed_m_s", 0.0))
        walks = o.fell is False and speed >= line
        ok += walks
        fell = f"fell {o.fell_at_s:6.2f} s" if o.fell_at_s is not None else (
            "stopped" if o.fell else "")
        if o.error:
            fell = f"error: {o.error}"
        print(f"{o.condition.name:38s} {'WALKS' if walks else 'falls' if o.fell else 'slow':5s}"
              f" {fell:16s} {speed:6.3f} m/s")
    print(f"{a.robot} {a.gait} {a.impulse:g} N*s balance={'off' if a.open_loop else 'on'}"
          f" {' '.join(a.set)}: {ok}/{len(outs)} survived and walking on (>= {line} m/s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
