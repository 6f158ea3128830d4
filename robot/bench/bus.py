"""Bus benchmark over the pty emulator (18 servos): our driver against the raw SDK calls.

Per cycle: sync write alone, and sync write + state read, as µs (median, p99) for our
``write_goals`` / ``read_state`` and for the SDK's group objects used the same way on the
same port in the same run (interleaved, so load drift hits both), plus the bytes our
driver puts on the wire per write (emulator counter) against the protocol minimum.

``python -m robot.bench.bus [--cycles N] [--protocol dynamixel|feetech]`` prints JSON.
Timings are of a Python emulator on a pty, not of a real wire: the ratios are the point.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from robot.bus.factory import make_bus
from robot.bus.sdk.bus import SdkBus
from robot.bus.servo_map import ServoMap
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot_file import load_robot

#: Protocol minimum for a position sync write of n servos [bytes].
MIN_WRITE_BYTES: dict[str, Callable[[int], int]] = {
    "dynamixel": lambda n: 14 + 5 * n,
    "feetech": lambda n: 8 + 3 * n,
}
BLOCK = 20  # writes between emulator drains (keeps the pty buffer from filling)


def _stats(ns: list[int]) -> dict[str, float]:
    us = np.asarray(ns, dtype=float) / 1e3
    return {"median": round(float(np.median(us)), 1),
            "p99": round(float(np.percentile(us, 99)), 1)}


class _RawSdk:
    """The SDK's own GroupSyncWrite / GroupSyncRead on our bus's port, used plainly."""

    def __init__(self, bus: SdkBus, ids: tuple[int, ...]) -> None:
        goal = bus.table["goal_position"]
        first, last = (bus.table[n] for n in bus.state_block)
        self.ids = ids
        self.size = goal.size
        self.fields = [bus.table[n] for n in ("present_position", "present_load",
                                              "present_temperature")]
        self.writer = bus.sdk.GroupSyncWrite(bus.port_handler, bus.packet_handler,
                                             goal.address, goal.size)
        self.reader = bus.sdk.GroupSyncRead(bus.port_handler, bus.packet_handler,
                                            first.address,
                                            last.address + last.size - first.address)
        for sid in ids:
            self.reader.addParam(sid)
        self.ok = bus.sdk.COMM_SUCCESS

    def write(self, goals: dict[int, int]) -> None:
        self.writer.clearParam()
        for sid, t in goals.items():
            self.writer.addParam(sid, list(t.to_bytes(self.size, "little")))
        self.writer.txPacket()

    def read(self) -> dict[int, list[int]]:
        if self.reader.txRxPacket() != self.ok:
            raise RuntimeError("raw SDK sync read failed")
        return {sid: [self.reader.getData(sid, r.address, r.size) for r in self.fields]
                for sid in self.ids}


def _drain(emu: Any, count: int) -> None:
    """Wait until the emulator has parsed ``count`` sync writes in total."""
    end = time.monotonic() + 10
    while emu.counters().get("sync_write", 0) < count and time.monotonic() < end:
        time.sleep(0.002)


def run_bus_bench(protocol: str, *, cycles: int = 500) -> dict[str, Any]:
    """Benchmark one protocol over a fresh emulator; returns figures in µs and bytes."""
    from sim.emulator.chain import Emulator

    robot = load_robot(ROBOTS_DIR / f"biped18-{protocol}.toml")
    sm = ServoMap(robot)
    poses = [sm.goals((sm.vector(robot.rest) * s).tolist()) for s in (0.0, 0.5)]
    ids, n = robot.ids, len(robot.ids)
    with Emulator(protocol, robot) as emu:
        bus = make_bus(protocol, robot=robot, port=emu.port, timeout_ms=100)
        assert isinstance(bus, SdkBus)
        bus.open()
        raw = _RawSdk(bus, ids)
        t_ours: list[int] = []
        t_raw: list[int] = []
        rx0 = emu.counters()["rx_bytes"]
        sent = emu.counters().get("sync_write", 0)
        ours_bytes = 0
        for k in range(cycles):
            g = poses[k % 2]
            a = time.perf_counter_ns()
            bus.write_goals(g)
            b = time.perf_counter_ns()
            raw.write(g)
            c = time.perf_counter_ns()
            t_ours.append(b - a)
            t_raw.append(c - b)
            sent += 2
            if k % BLOCK == BLOCK - 1 or k == cycles - 1:
                _drain(emu, sent)
        ours_bytes = (emu.counters()["rx_bytes"] - rx0) // 2  # both wrote the same packets
        rw_ours: list[int] = []
        rw_raw: list[int] = []
        for k in range(cycles):
            g = poses[k % 2]
            a = time.perf_counter_ns()
            bus.write_goals(g)
            bus.read_state(ids)
            b = time.perf_counter_ns()
            raw.write(g)
            raw.read()
            c = time.perf_counter_ns()
            rw_ours.append(b - a)
            rw_raw.append(c - b)
        bus.close()
    w, wr = _stats(t_ours), _stats(rw_ours)
    rw, rwr = _stats(t_raw), _stats(rw_raw)
    return {
        "protocol": protocol, "servos": n, "cycles": cycles,
        "write_us": w, "raw_write_us": rw,
        "write_ratio": round(w["median"] / rw["median"], 2),
        "write_read_us": wr, "raw_write_read_us": rwr,
        "write_read_ratio": round(wr["median"] / rwr["median"], 2),
        "write_bytes_per_cycle": round(ours_bytes / cycles, 1),
        "write_bytes_min": MIN_WRITE_BYTES[protocol](n),
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m robot.bench.bus", description=__doc__)
    p.add_argument("--cycles", type=int, default=500)
    p.add_argument("--protocol", choices=tuple(MIN_WRITE_BYTES), action="append")
    args = p.parse_args(argv)
    results = [run_bus_bench(proto, cycles=args.cycles)
               for proto in (args.protocol or list(MIN_WRITE_BYTES))]
    sys.stdout.write(json.dumps(results, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
