"""Benchmarks of the kinematic core: one control tick, and vectorised curve evaluation.

Speed is reported as percentiles and rates, never asserted in unit tests.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from robot.bench.legs import OFFSETS, offset_legs
from robot.bus.servo_map import ServoMap
from robot.config.bundled import ROBOTS_DIR
from robot.config.gait_file import load_gait
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.gait import vectorised
from robot.gait.engine import GaitEngine, within_steering_budget


def percentiles_us(samples_s: list[float] | np.ndarray) -> dict[str, float]:
    """Median, p99 and max of durations given in seconds, in µs."""
    a = np.asarray(samples_s) * 1e6
    return {"median_us": float(np.median(a)), "p99_us": float(np.percentile(a, 99)),
            "max_us": float(a.max())}


def _ticker(robot: RobotConfig, gait: str, dt: float) -> Callable[[], object]:
    """One tick of ``robot``'s gait engine and servo map, warmed up to full amplitude."""
    engine = GaitEngine(robot, load_gait(gait).for_robot(robot))
    smap = ServoMap(robot)
    engine.start()
    for _ in range(500):  # warm up, and ramp in to full amplitude
        smap.goals(engine.tick(dt))
    return lambda: smap.goals(engine.tick(dt))


def _time_ticks(tick: Callable[[], object], ticks: int) -> list[float]:
    samples = []
    clock = time.perf_counter
    for _ in range(ticks):
        t0 = clock()
        tick()
        samples.append(clock() - t0)
    return samples


def bench_tick(*, ticks: int = 20000, robot_path: str | None = None,
               gait: str = "walk", dt: float = 0.005) -> dict[str, Any]:
    """One tick of gait + targets + IK + tick mapping, timed one by one."""
    robot = load_robot(robot_path)
    samples = _time_ticks(_ticker(robot, gait, dt), ticks)
    return {"joints": len(robot.joints), "ticks": ticks, **percentiles_us(samples)}


def bench_ticks(*, ticks: int = 20000, gait: str = "walk", dt: float = 0.005,
                rounds: int = 10) -> dict[str, Any]:
    """``bench_tick`` for every bundled robot, and for the default robot with the offset
    legs of robot.bench.legs; those are timed back to back with the default robot's box
    legs, in ``rounds`` alternating slices, and reported with the ratio of the medians
    (meaningful on a loaded machine, where the microseconds are not)."""
    out: dict[str, Any] = {}
    for path in sorted(ROBOTS_DIR.glob("*.toml")):
        robot = load_robot(str(path))
        out[path.stem] = {"joints": len(robot.joints), "ticks": ticks,
                          "legs": "box" if all(leg.simple for leg in robot.legs) else "chain",
                          **percentiles_us(_time_ticks(_ticker(robot, gait, dt), ticks))}
    base = load_robot(None)
    for name in OFFSETS:
        box, offset = _ticker(base, gait, dt), _ticker(offset_legs(base, name), gait, dt)
        box_s: list[float] = []
        offset_s: list[float] = []
        for _ in range(rounds):
            box_s += _time_ticks(box, ticks // rounds)
            offset_s += _time_ticks(offset, ticks // rounds)
        got, ref = percentiles_us(offset_s), percentiles_us(box_s)
        out[f"{base.name} with {name} legs"] = {
            "ticks": len(offset_s), **got, "box_legs_median_us": ref["median_us"],
            "ratio_to_box_legs": got["median_us"] / ref["median_us"]}
    return out


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
    params = load_gait(gait).for_robot(robot)
    engine = GaitEngine(robot, params)
    times = np.linspace(0.0, frames / 100.0, frames)
    best = _best_s(lambda: engine.curves(times, with_channels=False), repeats)
    one = _best_s(lambda: vectorised.curves(robot, within_steering_budget(params), times,
                                            with_channels=False, workers=1), repeats)
    return {"frames": frames, "threads": vectorised.default_workers(), "seconds": best,
            "frames_per_s": frames / best, "frames_per_s_one_thread": frames / one}


def run_core_bench(*, quick: bool = False) -> dict[str, Any]:
    return {
        "tick": bench_ticks(ticks=2000 if quick else 20000),
        "vectorised": bench_vectorised(frames=100_000 if quick else 1_000_000),
    }


def run_bus_section(*, quick: bool = False) -> dict[str, Any]:
    """Our bus driver vs the raw SDK group calls, over the pty emulator (both protocols)."""
    from robot.bench.bus import run_bus_bench

    cycles = 100 if quick else 500
    return {p: run_bus_bench(p, cycles=cycles) for p in ("dynamixel", "feetech")}
