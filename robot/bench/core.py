"""Benchmarks of the kinematic core: one control tick, and vectorised curve evaluation.

Speed is reported as percentiles and rates, never asserted in unit tests.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from robot.bus.servo_map import ServoMap
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait import vectorised
from robot.gait.engine import GaitEngine, within_steering_budget


def percentiles_us(samples_s: list[float] | np.ndarray) -> dict[str, float]:
    """Median, p99 and max of durations given in seconds, in µs."""
    a = np.asarray(samples_s) * 1e6
    return {"median_us": float(np.median(a)), "p99_us": float(np.percentile(a, 99)),
            "max_us": float(a.max())}


def bench_tick(*, ticks: int = 20000, robot_path: str | None = None,
               gait: str = "walk", dt: float = 0.005) -> dict[str, Any]:
    """One tick of gait + targets + IK + tick mapping, timed one by one."""
    robot = load_robot(robot_path)
    engine = GaitEngine(robot, load_gait(gait).params)
    smap = ServoMap(robot)
    engine.start()
    for _ in range(500):  # warm up, and ramp in to full amplitude
        smap.goals(engine.tick(dt))
    samples = []
    clock = time.perf_counter
    for _ in range(ticks):
        t0 = clock()
        smap.goals(engine.tick(dt))
        samples.append(clock() - t0)
    return {"joints": len(robot.joints), "ticks": ticks, **percentiles_us(samples)}


def _best_s(run: Callable[[], object], repeats: int) -> float:
    """The shortest of ``repeats`` runs [s]."""
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - t0)
    return best


def bench_vectorised(*, frames: int = 1_000_000, repeats: int = 3,
                     robot_path: str | None = None, gait: str = "walk") -> dict[str, Any]:
    """Joint angles for ``frames`` samples at once (best of ``repeats``): as
    ``GaitEngine.curves`` runs them (one thread per CPU), and on one thread."""
    robot = load_robot(robot_path)
    params = load_gait(gait).params
    engine = GaitEngine(robot, params)
    times = np.linspace(0.0, frames / 100.0, frames)
    best = _best_s(lambda: engine.curves(times, with_channels=False), repeats)
    one = _best_s(lambda: vectorised.curves(robot, within_steering_budget(params), times,
                                            with_channels=False, workers=1), repeats)
    return {"frames": frames, "threads": vectorised.default_workers(), "seconds": best,
            "frames_per_s": frames / best, "frames_per_s_one_thread": frames / one}


def run_core_bench(*, quick: bool = False) -> dict[str, Any]:
    return {
        "tick": bench_tick(ticks=2000 if quick else 20000),
        "vectorised": bench_vectorised(frames=100_000 if quick else 1_000_000),
    }


def run_bus_section(*, quick: bool = False) -> dict[str, Any]:
    """Our bus driver vs the raw SDK group calls, over the pty emulator (both protocols)."""
    from robot.bench.bus import run_bus_bench

    cycles = 100 if quick else 500
    return {p: run_bus_bench(p, cycles=cycles) for p in ("dynamixel", "feetech")}
