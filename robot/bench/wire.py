"""Reply timing of the emulator: pings through the real SDK on the pty, against what a real
wire takes (the instruction's and the reply's bytes at 10 bits each, plus the return delay).

``run_wire_bench`` pings one servo of an 18-servo Dynamixel chain at 1 Mbps ``count`` times
(3000 by default) and reports the round trip p50 / p99 / max [ms] beside the wire time,
and how late the emulator released replies against their wire-time schedule (the rest of
a round trip is the SDK and the OS); the issue's target is p99 under 1 ms on an idle
machine (a figure, never a test assertion).

``python -m robot.bench.wire [--count N]`` prints JSON.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

import numpy as np

from robot.bus.factory import make_bus
from robot.bus.sdk.bus import SdkBus
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot_file import load_robot

#: Dynamixel Protocol 2.0 ping: instruction 10 bytes, status with model and firmware 14.
PING_BYTES = 10 + 14
BAUD = 1_000_000


def run_wire_bench(*, quick: bool = False, count: int | None = None) -> dict[str, Any]:
    """Ping round trips [ms] over the emulator at 1 Mbps (return delay 0)."""
    from sim.emulator.chain import Emulator

    n = count or (300 if quick else 3000)
    robot = load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")
    with Emulator("dynamixel", robot, baud=BAUD) as emu:
        bus = make_bus("dynamixel", robot=robot, port=emu.port, baud=BAUD, timeout_ms=100,
                       check_health=False)
        assert isinstance(bus, SdkBus)
        bus.open()
        try:
            times = []
            missed = 0
            for k in range(n):
                a = time.perf_counter()
                ok = bus.ping(robot.ids[k % len(robot.ids)]) is not None
                times.append(time.perf_counter() - a)
                missed += not ok
            late = emu.counters()
        finally:
            bus.close(torque_off=False)
    ms = np.asarray(times) * 1e3
    wire_ms = PING_BYTES * 10 / BAUD * 1e3
    return {"pings": n, "baud": BAUD, "wire_ms": round(wire_ms, 3),
            "p50_ms": round(float(np.percentile(ms, 50)), 3),
            "p99_ms": round(float(np.percentile(ms, 99)), 3),
            "max_ms": round(float(ms.max()), 3),
            "faster_than_wire": int((ms < wire_ms).sum()), "missed": missed,
            "emulator_late_max_ms": late["late_max_us"] / 1e3,
            "emulator_late_over_1ms": late["late_over_1ms"]}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m robot.bench.wire", description=__doc__)
    p.add_argument("--count", type=int, default=3000)
    args = p.parse_args(argv)
    sys.stdout.write(json.dumps(run_wire_bench(count=args.count), indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
