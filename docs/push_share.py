"""The push map's goal checked in one walk per cell (issue 32): every direction and phase
pushed at a share of its own 1-step capture limit (robot.tuning.push_map: the limit from
an unpushed walk's state at that moment), walked as the map walks it (`biped walk --json
--stop-on-fall`, the push at 8 s + the phase, 2 s after it, the walking rule against the
unpushed walk's speed). A cell that walks on at 0.8 of its limit meets the goal's 80 %
(survival taken as falling off with the impulse, as the map's bisection takes it).

Run: ``MUJOCO_GL=egl nice -n 10 .venv/bin/python docs/push_share.py --robot
biped18-dynamixel --share 0.8 --jobs 2 [--set bal_brace_xi=0.03 ...] [--phases 0,0.25]
[--directions 0,90] [--open-loop]``

Prints per phase a row of the 8 directions (W: walks on, s: stood, f: fell) and the
count.
"""

from __future__ import annotations

import argparse
import multiprocessing
import sys
from concurrent.futures import ProcessPoolExecutor

from robot.balance.capture_limit import limits, numbers
from robot.commands.common import parse_sets
from robot.commands.push_map import directions as parse_directions
from robot.commands.push_map import phases as parse_phases
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.config.world import PUSH_AT_S
from robot.tuning.conditions import WALK_ON_SHARE
from robot.tuning.push_map import DIRECTIONS_DEG, PHASES, MapJob, state_of, verdict
from robot.tuning.robustness import Outcome, worker_init


def walk(job: MapJob) -> Outcome:
    return job.walk()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--robot", default="biped18-dynamixel")
    ap.add_argument("--gait", default="walk")
    ap.add_argument("--share", type=float, default=0.8)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    ap.add_argument("--open-loop", action="store_true")
    ap.add_argument("--phases", type=parse_phases, default=PHASES)
    ap.add_argument("--directions", type=parse_directions, default=DIRECTIONS_DEG)
    a = ap.parse_args()
    worker_init()
    robot = load_robot(a.robot)
    params = load_gait(a.gait).for_robot(robot)
    if a.set:
        params = params.replace(parse_sets(a.set), where="--set")
    n = numbers(robot, params.stance, params.foot_spread)
    cycle, balance = params.cycle_s, not a.open_loop
    refs = [MapJob(a.robot, a.gait, params, balance, float(f"{PUSH_AT_S + ph * cycle:.3f}"))
            for ph in a.phases]
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(a.jobs, mp_context=ctx, initializer=worker_init) as pool:
        ref_out = list(pool.map(walk, refs))
        jobs, lims = [], []
        for ref, o in zip(refs, ref_out, strict=True):
            state = state_of(o)
            for deg in a.directions:
                lim = limits(state, n, deg)[1] if state is not None else 0.0
                lims.append(lim)
                jobs.append(MapJob(a.robot, a.gait, params, balance, ref.at_s, deg,
                                   round(a.share * lim, 3)))
        outs = list(pool.map(walk, jobs))
    total = ok = 0
    print(f"{'phase':>8} " + " ".join(f"{d:>5g}" for d in a.directions))
    for i, o in enumerate(ref_out):
        line = WALK_ON_SHARE * o.speed_m_s
        row = []
        for k in range(len(a.directions)):
            v = verdict(outs[i * len(a.directions) + k], line)
            row.append({"walks": "W", "stood": "s", "fell": "f"}.get(v, "?"))
            ok += v == "walks"
            total += 1
        lim_row = lims[i * len(a.directions):(i + 1) * len(a.directions)]
        print(f"{a.phases[i]:>8.4f} " + " ".join(f"{c:>5}" for c in row)
              + "   limits " + " ".join(f"{x:.2f}" for x in lim_row))
    print(f"{a.robot} {a.gait} share {a.share:g} balance={'on' if balance else 'off'} "
          f"{' '.join(a.set)}: {ok}/{total} walk on at {a.share:g} x their 1-step limit"
          f" (median limit {sorted(lims)[len(lims) // 2]:.2f} N*s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
