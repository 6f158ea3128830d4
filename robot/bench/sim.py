"""Benchmark of the simulated walk (`biped bench --only sim`): how much faster than real
time one process walks, open loop and with balance (IMU + feedback), and which share of
the time MuJoCo's own stepping takes (its timers) versus everything else in the loop.

Each configuration runs ``repeats`` times; reported as the median and the spread of the
realtime factor (sim seconds / wall seconds of the loop) and the physics share. Machines
are shared: compare ratios measured in one run, never absolute numbers across machines.
"""

from __future__ import annotations

import statistics
import time
from typing import Any

from robot.balance.stage import Balance, attitude_reader
from robot.bus.factory import make_bus
from robot.bus.servo_map import ServoMap
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.imu import open_imu
from robot.loop.streamer import Streamer


def _walk(robot_name: str, seconds: float, *, balance: bool) -> tuple[float, float]:
    """(realtime factor, share of the loop's wall time spent in mj_step)."""
    import mujoco

    robot = load_robot(robot_name)
    bus: Any = make_bus("sim", robot=robot)
    with bus:
        engine = GaitEngine(robot, load_gait("walk").params)
        feedback = None
        imu = None
        if balance and robot.imu is not None:
            imu = open_imu(robot.imu, bus=bus)
            imu.open()
            feedback = Balance(engine, attitude_reader(imu))
        streamer = Streamer(ServoMap(robot), bus, engine, rate_hz=200.0, feedback=feedback)
        t0 = time.perf_counter()
        stats = streamer.run(seconds=seconds)
        wall = time.perf_counter() - t0
        physics = float(bus.data.timer[mujoco.mjtTimer.mjTIMER_STEP].duration)
        if imu is not None:
            imu.close()
    return stats.duration_s / wall, physics / wall


def run_sim_bench(*, quick: bool = False) -> dict[str, Any]:
    seconds, repeats = (1.0, 1) if quick else (20.0, 5)
    out: dict[str, Any] = {"walk_seconds": seconds, "repeats": repeats}
    for robot in ("biped18-dynamixel", "biped18-feetech"):
        for balance in (False, True):
            runs = [_walk(robot, seconds, balance=balance) for _ in range(repeats)]
            factors = sorted(r[0] for r in runs)
            out[f"{robot} {'balance' if balance else 'open loop'}"] = {
                "realtime_factor_median": round(statistics.median(factors), 2),
                "realtime_factor_min_max": [round(factors[0], 2), round(factors[-1], 2)],
                "mj_step_share_of_loop": round(statistics.median(r[1] for r in runs), 3),
            }
    return out
