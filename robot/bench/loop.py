"""Benchmark of the control loop: the real streamer on the pty emulator (18 servos, real
SDK) write-only at 1 kHz and write + read at 200 Hz, and the MuJoCo walk's realtime factor.

Reported as achieved rate / target, period-error percentiles and overruns: never asserted.
"""

from __future__ import annotations

import time
from typing import Any

from robot.bus.factory import make_bus
from robot.bus.servo_map import ServoMap
from robot.config.bundled import ROBOTS_DIR
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.loop.streamer import Streamer

NO_READS = 10**9  # read_every that never reads back


def _loop(protocol: str, *, rate_hz: float, read_every: int, seconds: float) -> dict[str, Any]:
    from sim.emulator.chain import Emulator

    robot = load_robot(ROBOTS_DIR / f"biped18-{protocol}.toml")
    with Emulator(protocol, robot) as emu:
        bus = make_bus(protocol, robot=robot, port=emu.port)
        with bus:
            engine = GaitEngine(robot, load_gait("walk").params)
            streamer = Streamer(ServoMap(robot), bus, engine, rate_hz=rate_hz,
                                read_every=read_every)
            stats = streamer.run(seconds=seconds)
    return {
        "target_hz": rate_hz,
        "achieved_share": round(stats.achieved_hz / rate_hz, 4),
        "period_error_p50_ms": round(stats.period_error_p50_ms, 4),
        "period_error_p99_ms": round(stats.period_error_p99_ms, 4),
        "period_error_max_ms": round(stats.period_error_max_ms, 4),
        "overruns": stats.overruns,
        "ticks": stats.ticks,
        "bus_errors": stats.bus_errors,
    }


def _sim_walk(seconds: float) -> dict[str, Any]:
    robot = load_robot()
    bus = make_bus("sim", robot=robot)
    t0 = time.perf_counter()
    with bus:
        engine = GaitEngine(robot, load_gait("walk").params)
        stats = Streamer(ServoMap(robot), bus, engine, rate_hz=200.0).run(seconds=seconds)
    wall = time.perf_counter() - t0
    return {"sim_seconds": round(stats.duration_s, 3), "wall_seconds": round(wall, 3),
            "realtime_factor": round(stats.duration_s / wall, 2)}


def run_loop_bench(*, quick: bool = False) -> dict[str, Any]:
    seconds = 1.0 if quick else 5.0
    out: dict[str, Any] = {}
    for protocol in ("dynamixel", "feetech"):
        out[protocol] = {
            "write_only_1khz": _loop(protocol, rate_hz=1000.0, read_every=NO_READS,
                                     seconds=seconds),
            "write_read_200hz": _loop(protocol, rate_hz=200.0, read_every=1, seconds=seconds),
        }
    out["sim_walk"] = _sim_walk(5.0 if quick else 20.0)
    return out
