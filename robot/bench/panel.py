"""Benchmark: does the panel's audience slow the control loop?

The panel walks the robot on the pty emulator (18 Dynamixels, the real SDK, wall clock)
at 200 Hz, and N clients in another process watch it, either as the old page did
(polling ``/api/state`` every 100 ms after each answer) or as the page does now (one
WebSocket each on ``/api/live``). Reported per (mode, N): the loop's overruns in the
window (its own count), the gaps between goal packets at the wire (the emulator's log:
the period the servos see), and how many state snapshots the server made; never asserted.

``python -m robot.bench.panel [--seconds S] [--clients 0,20,50]`` prints JSON; `biped bench
--only panel` runs it too.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
from pathlib import Path
from typing import Any

import numpy as np

from robot.config.bundled import ROBOTS_DIR
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.panel.controller import BusSpec, LoopOptions, make_controller
from robot.panel.server import build_server, serve_in_thread
from robot.panel.studio import Studio

POLL_S = 0.1  # the old page: the next poll 100 ms after each answer
GOAL_ADDRESS = 116  # Dynamixel X Goal Position (e-Manual)


def _client_main(mode: str, n: int, base: str, seconds: float) -> None:
    """In the client process: ``n`` watchers for ``seconds``; prints what they received."""
    stop = time.monotonic() + seconds
    got = [0] * n

    def poll(i: int) -> None:
        while time.monotonic() < stop:
            with urllib.request.urlopen(base + "api/state", timeout=10) as r:
                r.read()
            got[i] += 1
            time.sleep(POLL_S)

    def live(i: int) -> None:
        from websockets.sync.client import connect
        from websockets.typing import Origin

        url = base.replace("http://", "ws://") + "api/live"
        with connect(url, origin=Origin(base.rstrip("/")), open_timeout=20) as ws:
            while time.monotonic() < stop:
                ws.recv(timeout=10)
                got[i] += 1

    threads = [threading.Thread(target=poll if mode == "poll" else live, args=(i,))
               for i in range(n)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    print(json.dumps({"received": sum(got)}))


def _window(mode: str, n: int, seconds: float) -> dict[str, Any]:
    from sim.emulator.chain import Emulator

    robot = load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")
    with Emulator("dynamixel", robot) as emu, tempfile.TemporaryDirectory() as tmp:
        controller = make_controller(
            robot, BusSpec("dynamixel", port=emu.port, options={"timeout_ms": 50.0}),
            load_gait("walk").params, options=LoopOptions(rate_hz=200.0, read_every=10))
        server = build_server(controller, port=0, studio=Studio(
            controller, takes_dir=Path(tmp) / "t", keys_dir=Path(tmp) / "k"))
        _, base = serve_in_thread(server)
        hub = server.hub
        try:
            controller.start()
            end = time.monotonic() + 20
            while controller.state()["state"] != "walking" and time.monotonic() < end:
                time.sleep(0.05)
            client = None
            if n:
                client = subprocess.Popen(
                    [sys.executable, "-m", "robot.bench.panel", "--client", mode, str(n),
                     base, str(seconds + 1.0)], stdout=subprocess.PIPE, text=True)
                time.sleep(1.0)  # let them connect
            frames0, before = hub.frames, controller.loop_state(max_age=0.0)
            t0 = time.monotonic()
            emu.log(clear=True)
            time.sleep(seconds)
            after = controller.loop_state(max_age=0.0)
            goals = [p.t for p in emu.log() if p.instruction == "sync_write"
                     and p.address == GOAL_ADDRESS and p.t >= t0]
            frames = hub.frames - frames0
            received = 0
            if client is not None:
                out, _ = client.communicate(timeout=60)
                received = json.loads(out.strip().splitlines()[-1])["received"]
            running = controller.running
        finally:
            server.shutdown()
            server.server_close()
            controller.shutdown(timeout=10)
    gaps = np.diff(goals) * 1e3 if len(goals) > 1 else np.zeros(1)
    return {"mode": mode, "clients": n, "seconds": seconds, "goals": len(goals),
            "overruns": after["tel"].get("overruns", 0) - before["tel"].get("overruns", 0),
            "goal_gap_p50_ms": round(float(np.percentile(gaps, 50)), 3),
            "goal_gap_p99_ms": round(float(np.percentile(gaps, 99)), 3),
            "goal_gap_max_ms": round(float(gaps.max()), 3),
            "received_by_clients": received, "live_snapshots": frames,
            "loop_still_running": running}


def run_panel_bench(*, quick: bool = False, clients: tuple[int, ...] = (0, 20, 50),
                    seconds: float | None = None) -> dict[str, Any]:
    secs = seconds or (3.0 if quick else 10.0)
    out: dict[str, Any] = {}
    for n in clients:
        for mode in ("poll", "ws") if n else ("poll",):
            key = "idle" if not n else f"{mode}_{n}"
            out[key] = _window(mode, n, secs)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(prog="python -m robot.bench.panel")
    ap.add_argument("--client", nargs=4, metavar=("MODE", "N", "BASE", "SECONDS"))
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--clients", default="0,20,50")
    a = ap.parse_args()
    if a.client:
        mode, n, base, secs = a.client
        _client_main(mode, int(n), base, float(secs))
        return
    counts = tuple(int(c) for c in a.clients.split(","))
    print(json.dumps(run_panel_bench(clients=counts, seconds=a.seconds), indent=2))


if __name__ == "__main__":
    main()
