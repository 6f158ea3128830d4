"""The push map (`biped robustness --push-map`): for every direction and phase of the
step, the largest push the robot survives and walks on after, found by bisection, beside
its capture limit at that moment (robot.balance.capture_limit).

A cell is one direction (0 forward, 90 left, in the heading frame) and one phase (a
fraction of the gait cycle after PUSH_AT_S of gait), the push at gait time
``at_s`` = PUSH_AT_S + phase x cycle, as `biped walk --push AT:JX,JY` takes it, and the
walk AFTER_PUSH_S longer (each run is ``robot.tuning.robustness.run_condition``: `biped
walk --json --stop-on-fall`). Per phase and balance mode one unpushed walk of the same
length (a push of 0 N*s, which records the body's state at that moment) gives the state
for the limits and the speed a pushed walk must keep: it survives if it does not fall,
no servo fault stops it, and it walks at WALK_ON_SHARE of that walk's speed or faster
(the suite's walking rule). The bisection starts from [0, 1.25 x the cell's 1-step limit]
(widened while its top survives, up to PUSH_MAX_N_S) and halves it until it is
``resolution`` wide (0.05 N*s); a push that the robot survives above one it does not is
not looked for (survival taken as falling off with the impulse). Cells run in parallel
(one bisection per worker process, its walks one after the other).
"""

from __future__ import annotations

import dataclasses
import math
import multiprocessing
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from typing import Any

from robot.balance.capture_limit import Numbers, PushState, limits, numbers
from robot.config.params import GaitParams
from robot.config.robot_file import load_robot
from robot.config.world import PUSH_AT_S, Push, World
from robot.tuning.conditions import AFTER_PUSH_S, WALK_ON_SHARE, Condition
from robot.tuning.robustness import Outcome, WalkJob, run_condition, worker_init

DIRECTIONS_DEG = tuple(float(d) for d in range(0, 360, 45))
PHASES = tuple(k / 16 for k in range(16))
RESOLUTION_N_S = 0.05
#: The largest push a bisection tries [N*s] (the --push option's range).
PUSH_MAX_N_S = 10.0
#: --quick: two directions, two phases, a coarser bisection, pushes sooner (the rhythm
#: is learned after the 3-cycle ramp and 2 cycles: 4.4 s of the `walk` preset).
QUICK_DIRECTIONS = (0.0, 90.0)
QUICK_PHASES = (0.0, 0.5)
QUICK_RESOLUTION_N_S = 0.25
QUICK_AT_S = 5.0


@dataclass(frozen=True)
class MapJob:
    """One walk of the map: robot, preset name and parameters, balance, the push's gait
    time [s], direction [deg] and impulse [N*s] (0: the unpushed reference)."""

    robot: str
    gait: str
    params: GaitParams
    balance: bool
    at_s: float
    direction_deg: float = 0.0
    impulse: float = 0.0

    def walk(self) -> Outcome:
        a = math.radians(self.direction_deg)
        jx = round(self.impulse * math.cos(a), 6)
        jy = round(self.impulse * math.sin(a), 6)
        push = Push(self.at_s, jx, jy)
        c = Condition("push map", f"push {self.impulse:g} N*s at {self.direction_deg:g} deg, "
                      f"{self.at_s:.3f} s", World(pushes=(push,)), walk_on=True)
        return run_condition(WalkJob(self.robot, self.gait, self.params,
                                     self.at_s + AFTER_PUSH_S, c, balance=self.balance))


@dataclass
class Cell:
    """One direction and phase in one balance mode: the survived impulse and the limits
    [N*s], the walks it took."""

    direction_deg: float
    phase: float
    at_s: float
    balance: bool
    survived_n_s: float = 0.0
    limit_n_s: dict[int, float] = field(default_factory=dict)
    walks: list[tuple[float, str]] = field(default_factory=list)   # (impulse, verdict)

    def as_dict(self) -> dict[str, Any]:
        one = self.limit_n_s.get(1, 0.0)
        return {"direction_deg": self.direction_deg, "phase": self.phase,
                "at_s": self.at_s, "balance": self.balance,
                "survived_n_s": self.survived_n_s,
                "limit_n_s": {str(k): v for k, v in sorted(self.limit_n_s.items())},
                "share_of_1_step": self.survived_n_s / one if one > 0 else None,
                "walks": [{"impulse_n_s": j, "verdict": v} for j, v in self.walks]}


def verdict(o: Outcome, line: float) -> str:
    """"walks", "fell", "stood" (under ``line`` m/s) or "error" for one walk."""
    if o.fell is None:
        return "error"
    if o.fell:
        return "fell"
    return "walks" if o.speed_m_s >= line else "stood"


def largest(ok: Callable[[float], bool], hi: float, resolution: float) -> float:
    """The largest impulse [N*s] on the ``resolution`` grid with ``ok`` true, taking ok
    true at 0 and false from some impulse on: from [0, hi] (hi rounded up to the grid),
    widened (doubled) while ok(hi) up to PUSH_MAX_N_S, halved until ``resolution`` wide."""
    lo = 0.0
    hi = round(min(resolution * max(1, math.ceil(hi / resolution - 1e-9)), PUSH_MAX_N_S), 6)
    up = ok(hi)
    while up and hi < PUSH_MAX_N_S:
        lo, hi = hi, round(min(2.0 * hi, PUSH_MAX_N_S), 6)
        up = ok(hi)
    if up:
        return hi
    while hi - lo > resolution + 1e-9:
        mid = round(resolution * round(0.5 * (lo + hi) / resolution), 6)
        if mid <= lo or mid >= hi:
            mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return round(lo, 6)


def bisect(job: MapJob, line: float, hi: float, resolution: float) -> Cell:
    """The cell's largest impulse that walks on (module doc), from the bracket [0, hi]."""
    cell = Cell(job.direction_deg, 0.0, job.at_s, job.balance)
    cache: dict[float, bool] = {}

    def ok(j: float) -> bool:
        j = round(j, 6)
        if j not in cache:
            v = verdict(dataclasses.replace(job, impulse=j).walk(), line)
            cell.walks.append((j, v))
            cache[j] = v == "walks"
        return cache[j]
    cell.survived_n_s = largest(ok, hi, resolution)
    return cell


def _reference(job: MapJob) -> tuple[MapJob, Outcome]:
    return job, job.walk()


def _cell(args: tuple[MapJob, float, float, float]) -> Cell:
    return bisect(*args)


def push_map(robot: str, gait: str, params: GaitParams, *,
             directions: Sequence[float] = DIRECTIONS_DEG, phases: Sequence[float] = PHASES,
             balance_modes: Sequence[bool] = (True, False), jobs: int | None = None,
             resolution: float = RESOLUTION_N_S, at_s: float = PUSH_AT_S,
             progress: Callable[[Cell], None] | None = None) -> list[Cell]:
    """Every cell of the map (module doc), in order: balance mode, phase, direction."""
    cycle = params.cycle_s
    n = numbers(load_robot(robot), params.stance, params.foot_spread)
    refs = [MapJob(robot, gait, params, b, float(f"{at_s + ph * cycle:.3f}"))
            for b in balance_modes for ph in phases]
    jobs = jobs or os.cpu_count() or 1
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=jobs, mp_context=ctx,
                             initializer=worker_init) as pool:
        walked = list(pool.map(_reference, refs))
        tasks, cells = [], []
        for (ref, o), ph in zip(walked, [ph for _ in balance_modes for ph in phases],
                                strict=True):
            state = state_of(o)
            for deg in directions:
                lim = limits(state, n, deg) if state is not None else dict.fromkeys((0, 1, 2), 0.0)
                job = MapJob(robot, gait, params, ref.balance, ref.at_s, deg)
                cells.append((ph, lim, verdict(o, 0.0) == "walks"))
                tasks.append((job, WALK_ON_SHARE * o.speed_m_s, 1.25 * lim[1], resolution))
        done = []
        runnable = [t for t, (_, _, up) in zip(tasks, cells, strict=True) if up]
        results = iter(pool.map(_cell, runnable))
        for task, (ph, lim, up) in zip(tasks, cells, strict=True):
            job = task[0]
            cell = next(results) if up else Cell(job.direction_deg, 0.0, job.at_s, job.balance)
            cell.phase, cell.limit_n_s = ph, lim
            if progress is not None:
                progress(cell)
            done.append(cell)
    return done


def state_of(o: Outcome) -> PushState | None:
    """The body's state at the (0 N*s) push of a reference walk, if it got there."""
    applied = o.summary.get("world", {}).get("pushes_applied", [])
    return PushState.of(applied[0]["state"]) if applied and "state" in applied[0] else None


def limits_of(o: Outcome, n: Numbers) -> dict[int, float] | None:
    """The capture limits [N*s] of the push an outcome's walk took, in its direction
    (None if the walk had no push or it was not applied)."""
    applied = o.summary.get("world", {}).get("pushes_applied", [])
    if not applied or "state" not in applied[0]:
        return None
    p = applied[0]
    deg = math.degrees(math.atan2(float(p["jy"]), float(p["jx"])))
    return limits(PushState.of(p["state"]), n, deg)
